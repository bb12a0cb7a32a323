// The I/O driver types shipped with syncplc.
#pragma once

#include "runtime/core/io_driver.hpp"

namespace syncplc {

const DriverRegistry& builtin_drivers();

}  // namespace syncplc
