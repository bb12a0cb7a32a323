// Prints the set values of jerk-limited PLCopen moves for
// tests/plcopen/test_jerk_lp.py, which checks them against a linear program
// nobody here wrote (scipy's HiGHS). Reads one case a line from stdin:
//   T V A D J x0 goal
// and runs an AxisMachine on an ideal drive: power, MC_MoveAbsolute(goal, V,
// A, D, J) from rest at x0, scanned until the move is Done. Prints per case
//   case <remaining_scans at the start> <scans to Done> <final position>
// followed by one line "<position> <velocity>" per scan, the start first.
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>

#include "fblocks/plcopen/axis_machine.hpp"

using namespace syncplc::plcopen;

namespace {

struct Drive {
  bool on = false;
  double x = 0, v = 0;
  DriveFeedback fb() const {
    DriveFeedback f;
    f.position = x;
    f.velocity = v;
    f.power_on = on;
    return f;
  }
  void apply(const DriveCommand& c) {
    on = c.enable;
    x = c.position;
    v = c.velocity;
  }
};

int run_case(double T, double V, double A, double D, double J, double x0, double goal) {
  AxisLimits l;
  l.v_max = V;
  l.a_max = A;
  l.d_max = D;
  l.j_max = J;
  AxisMachine m(l, T);
  Drive d;
  d.x = x0;
  for (int i = 0; i < 5 && m.state() != AxisState::Standstill; ++i) {
    m.cycle(d.fb());
    m.request_power(true);
    d.apply(m.drive_command());
  }
  if (m.state() != AxisState::Standstill) return 1;
  Command c;
  c.kind = CommandKind::MoveAbsolute;
  c.position = goal;
  c.velocity = V;
  AxisError e = AxisError::None;
  const CommandId id = m.submit(c, &e);
  if (id == 0) {
    std::printf("error %u\n", static_cast<unsigned>(e));
    return 0;
  }
  const long long predicted = m.remaining_scans();
  std::ostringstream rows;
  rows.precision(17);
  rows << m.set_position() << ' ' << m.set_velocity() << '\n';
  long long scans = 0;
  while (m.report(id).status == CommandStatus::Active && scans < 10000000) {
    m.cycle(d.fb());
    m.request_power(true);
    d.apply(m.drive_command());
    ++scans;
    rows << m.set_position() << ' ' << m.set_velocity() << '\n';
  }
  std::printf("case %lld %lld %.17g\n%s", predicted, scans, m.set_position(), rows.str().c_str());
  return 0;
}

}  // namespace

int main() {
  std::string line;
  while (std::getline(std::cin, line)) {
    std::istringstream in(line);
    double T, V, A, D, J, x0, goal;
    if (!(in >> T >> V >> A >> D >> J >> x0 >> goal)) {
      std::fprintf(stderr, "bad case line: %s\n", line.c_str());
      return 2;
    }
    if (run_case(T, V, A, D, J, x0, goal) != 0) {
      std::fprintf(stderr, "the axis did not power up: %s\n", line.c_str());
      return 1;
    }
  }
  return 0;
}
