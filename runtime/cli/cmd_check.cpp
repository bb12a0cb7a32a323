#include <iostream>

#include "runtime/cli/commands.hpp"
#include "runtime/modbus/register_map.hpp"
#include "runtime/project/report.hpp"

namespace syncplc::cli {

int cmd_check(const std::string& project) {
  auto r = load_or_report(project, {});
  if (!r.ok()) return kExitInvalid;
  const Program& p = *r.program;
  std::cout << project << ": OK\n\n";
  print_task_table(std::cout, p);
  std::cout << "\n";
  print_execution_order(std::cout, p);
  std::cout << "\n";
  print_tag_map(std::cout, p);
  {
    std::vector<std::string> notes;
    ModbusMap map = ModbusMap::build(p, &notes);
    bool mapped = false;
    for (int t = 0; t < 4; ++t) mapped |= !map.points(static_cast<ModbusTable>(t)).empty();
    if (mapped || !notes.empty()) {
      std::cout << "\n";
      print_modbus_map(std::cout, p, map, WordOrder::HighFirst);
      for (const auto& n : notes) std::cout << "  not mapped: " << n << "\n";
    }
  }
  bool header = false;
  for (const auto& d : p.drivers) {
    std::string s = d.driver->summary();
    if (s.empty()) continue;
    if (!header) std::cout << "\nDrivers:\n";
    header = true;
    std::cout << "  " << d.driver->name() << " (" << d.type << "): " << s << "\n";
  }
  if (!p.traces.empty()) {
    std::cout << "\nTraces:";
    for (const auto& t : p.traces) std::cout << " " << t.label;
    std::cout << "\n";
  }
  return kExitOk;
}

}  // namespace syncplc::cli
