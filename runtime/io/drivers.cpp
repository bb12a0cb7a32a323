#include "runtime/io/drivers.hpp"

#include "runtime/io/dds/dds_driver.hpp"
#include "runtime/io/memory_driver.hpp"
#include "runtime/io/modbus_client/modbus_client.hpp"
#include "runtime/io/sim_ring.hpp"
#include "runtime/io/sim_table.hpp"

namespace syncplc {

const DriverRegistry& builtin_drivers() {
  static const DriverRegistry registry = [] {
    DriverRegistry r;
    r.add(memory_driver_type());
    r.add(sim_table_driver_type());
    r.add(sim_ring_driver_type());
    r.add(modbus_client_driver_type());
    r.add(dds_driver_type());
    return r;
  }();
  return registry;
}

}  // namespace syncplc
