#include "runtime/plc/driver_change.hpp"

namespace syncplc::plc {

std::vector<std::pair<std::size_t, std::size_t>> pair_takeovers(const Program& old, const Program& next,
                                                                const ProgramChange& change) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  std::vector<bool> old_taken(old.drivers.size(), false), new_taken(next.drivers.size(), false);
  auto pair_up = [&](bool same_name) {
    for (std::size_t b : change.new_drivers)
      for (std::size_t a : change.old_drivers) {
        if (old_taken[a] || new_taken[b] || old.drivers[a].type != next.drivers[b].type) continue;
        if (same_name && old.drivers[a].driver->name() != next.drivers[b].driver->name()) continue;
        out.emplace_back(a, b);
        old_taken[a] = new_taken[b] = true;
      }
  };
  pair_up(true);
  pair_up(false);
  return out;
}

bool DriverChange::prepare(ChangeContext& c, std::string* why) {
  Program& next = *c.next.program;
  pairs_ = pair_takeovers(c.from, next, c.change);
  for (const auto& [a, b] : pairs_) next.drivers[b].driver->will_take_over(*c.from.drivers[a].driver);
  opened_ = 0;
  for (std::size_t b : c.change.new_drivers) {
    IoDriver& d = *next.drivers[b].driver;
    std::string err;
    if (!d.open(&err)) {
      *why = "driver " + d.name() + ": " + err;
      abort(c);
      return false;
    }
    ++opened_;
  }
  return true;
}

void DriverChange::abort(ChangeContext& c) {
  Program& next = *c.next.program;
  for (std::size_t i = 0; i < opened_; ++i) next.drivers[c.change.new_drivers[i]].driver->close();
  opened_ = 0;
}

void DriverChange::complete(ChangeContext& c) {
  Program& next = *c.next.program;
  for (const auto& [a, b] : pairs_) next.drivers[b].driver->take_over(*c.from.drivers[a].driver);
  for (std::size_t a : c.change.old_drivers) c.from.drivers[a].driver->close();
  pairs_.clear();
}

void DriverChange::close_left_over(ChangeContext& c) { complete(c); }

}  // namespace syncplc::plc
