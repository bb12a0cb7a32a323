#include "runtime/project/online_change.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace syncplc {

std::string change_summary(const ProgramChange& c) {
  std::size_t fates[5] = {0, 0, 0, 0, 0};
  for (const auto& t : c.tasks) ++fates[static_cast<int>(t.fate)];
  std::string tasks;
  for (TaskFate f : {TaskFate::Kept, TaskFate::Retimed, TaskFate::Added, TaskFate::Removed, TaskFate::Restarted})
    if (fates[static_cast<int>(f)] || f == TaskFate::Kept)
      tasks += (tasks.empty() ? "" : ", ") + fmt::format("{} {}", fates[static_cast<int>(f)], task_fate_name(f));
  std::string out = fmt::format("instances: {} kept, {} retuned, {} rewired, {} new, {} removed; tasks: {}; {} tag value{} carried over",
                                c.count(InstanceFate::Kept), c.count(InstanceFate::Retuned), c.count(InstanceFate::Rewired),
                                c.count(InstanceFate::New),
                                c.count(InstanceFate::Removed), tasks, c.tags_carried, c.tags_carried == 1 ? "" : "s");
  if (!c.forces.empty()) {
    const auto kept = static_cast<std::size_t>(std::count_if(c.forces.begin(), c.forces.end(), [](const ForceChange& f) { return f.kept; }));
    out += fmt::format("; forces: {} kept, {} dropped", kept, c.forces.size() - kept);
  }
  return out;
}

std::vector<std::string> change_report(const ProgramChange& c) {
  std::vector<std::string> out;
  for (const auto& t : c.tasks)
    out.push_back(fmt::format("task {}: {}{}", t.name, task_fate_name(t.fate), t.detail.empty() ? "" : " (" + t.detail + ")"));
  for (const auto& i : c.instances)
    out.push_back(fmt::format("  {} ({}, task {}): {}{}", i.name, i.type, i.task, instance_fate_name(i.fate),
                              i.detail.empty() ? "" : " (" + i.detail + ")"));
  for (const auto& d : c.drivers) out.push_back(fmt::format("driver {}: {}", d.name, d.detail));
  for (const auto& f : c.forces)
    out.push_back(fmt::format("force {}: {} ({})", f.ref, f.kept ? "kept" : "dropped", f.detail));
  return out;
}

}  // namespace syncplc
