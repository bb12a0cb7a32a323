#include <iostream>

#include "runtime/cli/commands.hpp"
#include "runtime/modbus/register_map.hpp"
#include "runtime/project/report.hpp"
#include "runtime/project/system.hpp"

namespace syncplc::cli {
namespace {

// The server's settings, then the map in the server's word order.
void print_modbus(const Program& p, const ModbusSettings& s) {
  std::cout << "\nModbus TCP server: ";
  if (s.server.enabled) std::cout << modbus_settings_text(s.server) << "\n";
  else std::cout << (s.server.declared ? "off (enabled: false)" : "off (no modbus: section)") << "\n";
  std::vector<std::string> notes;
  ModbusMap map = ModbusMap::build(p, s, &notes);
  bool mapped = false;
  for (int t = 0; t < 4; ++t) mapped |= !map.points(static_cast<ModbusTable>(t)).empty();
  if (!mapped && notes.empty()) return;
  print_modbus_map(std::cout, p, map, s.server.word_order);
  for (const auto& n : notes) std::cout << "  not mapped: " << n << "\n";
}

// How the sources: run (docs/st.md, "How compiled ST runs").
void print_st(const StSummary& st) {
  if (st.files == 0) return;
  std::cout << "\nStructured Text: " << st.pous << (st.pous == 1 ? " POU" : " POUs") << " from " << st.files
            << (st.files == 1 ? " file" : " files") << ", ";
  if (!st.native_asked) {
    std::cout << "on the interpreter (project: st_engine: interpreter)\n";
  } else if (st.native_pous == 0) {
    std::cout << "on the interpreter: no native code here (it is made for x86-64, in memory the system lets a "
                 "process execute)\n";
  } else {
    std::cout << "as native code (x86-64): " << st.native_pous << " of " << st.pous << " POUs, "
              << st.register_loops
              << (st.register_loops == 1 ? " loop keeps its cells in registers\n" : " loops keep their cells in registers\n");
  }
}

// A system file: every node loads, and their topics match (docs/dds.md, "In virtual time").
int check_system(const std::string& path) {
  LoadedSystem sys = load_system_or_project(path, {});
  if (!sys.ok()) {
    for (const auto& d : sys.diagnostics.sorted()) std::cerr << d.text() << "\n";
    std::cerr << "syncplc: " << sys.diagnostics.size() << " error(s)\n";
    return kExitInvalid;
  }
  std::string err;
  if (!open_system(sys, &err)) {
    std::cerr << "syncplc: " << err << "\n";
    return kExitInvalid;
  }
  close_system(sys);
  std::cout << path << ": OK, system " << sys.name << " of " << sys.nodes.size() << " nodes, every subscription "
            << "published by a node with the same layout\n";
  for (const auto& n : sys.nodes) {
    const Program& p = *n.loaded.program;
    std::cout << "\nnode " << n.name << ": " << n.project << " (" << p.name << ")\n";
    for (const auto& t : p.tasks)
      std::cout << "  task " << t->config().name << ": " << format_duration(t->config().period_ns) << "\n";
    for (const auto& d : p.drivers) {
      std::string s = d.driver->summary();
      if (!s.empty()) std::cout << "  " << d.driver->name() << " (" << d.type << "): " << s << "\n";
    }
  }
  std::cout << "\n(syncplc check NODE.yaml shows a node in full)\n";
  return kExitOk;
}

}  // namespace

int cmd_check(const std::string& project) {
  if (is_system_file(project)) return check_system(project);
  auto r = load_or_report(project, {});
  if (!r.ok()) return kExitInvalid;
  const Program& p = *r.program;
  std::cout << project << ": OK\n\n";
  print_task_table(std::cout, p);
  std::cout << "\n";
  print_execution_order(std::cout, p);
  std::cout << "\n";
  print_tag_map(std::cout, p);
  print_modbus(p, r.modbus);
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
  print_st(r.st);
  return kExitOk;
}

}  // namespace syncplc::cli
