#include "runtime/plc/change_runner.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "runtime/core/iec_type.hpp"
#include "runtime/plc/project_versions.hpp"
#include "runtime/plc/store_link.hpp"
#include "runtime/project/online_change.hpp"
#include "runtime/project/report.hpp"

namespace syncplc::plc {

ChangeRunner::ChangeRunner(const ChangeRequest& request, Setup setup, const std::atomic<bool>* cancel)
    : store_(&setup.store), scheduler_(&setup.scheduler) {
  // What to load.
  ChangeSource src;
  switch (request.kind) {
    case ChangeRequest::Kind::Reload:
      src = {request.path.empty() ? setup.project : request.path, "reload", ""};
      break;
    case ChangeRequest::Kind::Load: src = {request.path, "upload", "an upload" + request.by}; break;
    case ChangeRequest::Kind::Rollback: {
      std::string why;
      bool missing = false;
      auto v = extract_version(setup.store.path(), request.version, &why, &missing);
      if (!v) {
        // No such version is the caller's mistake (404), not the PLC's state.
        refuse(missing ? 404 : 409, "rollback refused: " + why + "; the running program continues unchanged");
        return;
      }
      src = {v->project_file, "rollback", "version " + std::to_string(v->number) + request.by};
      break;
    }
  }
  what_ = src.what();
  project_file_ = src.path;
  LoadOptions options = setup.options;
  options.cancel = cancel;
  LoadResult next = load_project(src.path, options);
  auto record = [&](const LoadResult& r, bool accepted, const std::vector<std::string>& errors) {
    auto load = project_load(r, src.path, src.origin, src.source);
    load.accepted = accepted;
    if (!accepted && r.ok()) load.errors = errors;
    setup.store.record(std::move(load));
  };
  if (!next.ok()) {
    std::vector<std::string> lines;
    for (const auto& d : next.diagnostics.sorted()) lines.push_back(d.text());
    record(next, false, lines);
    std::string summary = fmt::format("reload of {} rejected ({} error{}); the running program continues unchanged",
                                      what_, lines.size(), lines.size() == 1 ? "" : "s");
    refuse(400, std::move(summary), std::move(lines));
    return;
  }
  // The PLC began to stop while the project loaded: nothing is prepared.
  auto stopping = [&] { return cancel && cancel->load(std::memory_order_relaxed); };
  if (stopping()) {
    refuse(409, "the PLC is stopping: the change of " + what_ + " was not made");
    return;
  }
  hash_ = store::make_content(next.sources).hash;
  auto load = project_load(next, src.path, src.origin, src.source);  // recorded once the change is committed
  tx_ = std::make_unique<Transaction>(setup.running, std::move(next), src);
  std::string why;
  if (!tx_->prepare(setup.participants, &why)) {
    load.accepted = false;
    load.errors = {why};
    setup.store.record(std::move(load));
    refuse(400, "reload of " + what_ + " rejected (" + why + "); the running program continues unchanged", {why});
    return;
  }
  if (stopping()) {
    tx_.reset();  // prepared, not committed: its destructor aborts every participant
    refuse(409, "the PLC is stopping: the change of " + what_ + " was not made");
    return;
  }
  tx_->commit(setup.scheduler);
  load.accepted = true;
  setup.store.record(std::move(load));
  // Each task switches at its first release at or after T, up to a period
  // after it: one later than that and a second is stuck in a scan.
  std::int64_t longest = 0;
  for (const auto& t : tx_->next().program->tasks) longest = std::max(longest, t->config().period_ns);
  give_up_ns_ = tx_->change().switch_ns + longest + 1'000'000'000;
}

ChangeRunner::~ChangeRunner() = default;

void ChangeRunner::refuse(int status, std::string summary, std::vector<std::string> lines) {
  ChangeResult r;
  r.accepted = false;
  r.status = status;
  r.summary = std::move(summary);
  r.lines = std::move(lines);
  result_ = std::move(r);
}

ChangeResult ChangeRunner::accepted_result(bool complete) {
  const ProgramChange& change = tx_->change();
  ChangeResult r;
  r.accepted = true;
  r.status = 200;
  r.lines = change_report(change);
  r.instances = change.instances;
  r.hash = hash_;
  // What the switch cost: how late each task's first new scan started (a
  // complete change has them all: a handover is finished after that scan).
  std::int64_t late = 0;
  std::string late_task;
  for (const auto& h : change.handovers) {
    const std::int64_t l = h->first_scan_late_ns.load(std::memory_order_relaxed);
    if (h->to && l > late) late = l, late_task = h->to->config().name;
  }
  r.lines.push_back(fmt::format("switch at {:.6f}s: the first scans of the new program started at most {}{} after their release",
                                static_cast<double>(change.switch_ns) * 1e-9, format_ns(late),
                                late_task.empty() ? "" : " (task " + late_task + ")"));
  r.summary = "reloaded " + what_ + ": " + change_summary(change);
  if (!complete) {
    std::string stuck;
    for (const auto& t : tx_->waiting_tasks()) stuck += (stuck.empty() ? "" : ", ") + t;
    r.summary += "; task " + stuck +
                 " has not reached the switch yet (a scan that does not end?): the change completes when it does";
  }
  return r;
}

bool ChangeRunner::poll() {
  if (!tx_ || tx_->phase() == ChangePhase::Aborted) return true;
  if (tx_->poll()) {
    if (!result_) result_ = accepted_result(true);
    return true;
  }
  if (!result_ && scheduler_->now_ns() > give_up_ns_) result_ = accepted_result(false);
  return false;
}

std::unique_ptr<Program> ChangeRunner::take_new_program() { return std::move(tx_->next().program); }

}  // namespace syncplc::plc
