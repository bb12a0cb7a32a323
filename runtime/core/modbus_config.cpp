#include "runtime/core/modbus_config.hpp"

namespace syncplc {

std::string_view modbus_table_name(ModbusTable t) {
  switch (t) {
    case ModbusTable::Coils: return "coil";
    case ModbusTable::DiscreteInputs: return "discrete input";
    case ModbusTable::InputRegisters: return "input register";
    case ModbusTable::HoldingRegisters: return "holding register";
  }
  return "?";
}

std::string_view modbus_table_key(ModbusTable t) {
  switch (t) {
    case ModbusTable::Coils: return "coil";
    case ModbusTable::DiscreteInputs: return "discrete_input";
    case ModbusTable::InputRegisters: return "input_register";
    case ModbusTable::HoldingRegisters: return "holding_register";
  }
  return "?";
}

std::string_view word_order_key(WordOrder o) { return o == WordOrder::HighFirst ? "high_first" : "low_first"; }

}  // namespace syncplc
