// One online change of a running PLC, from the request to its outcome: the
// project to load (the instance's file, a stored version for a rollback, an
// upload), the load and its checks, then the transaction (transaction.hpp)
// with the PLC's participants, stepped by the control thread without ever
// waiting for a switch. Every load goes to the project store, accepted or
// rejected with its errors.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "runtime/plc/change_request.hpp"
#include "runtime/plc/transaction.hpp"

namespace syncplc::plc {

class StoreLink;

class ChangeRunner {
 public:
  struct Setup {
    Program& running;
    const std::string& project;     // the instance's project file
    const LoadOptions& options;     // as the PLC loads (--set)
    StoreLink& store;
    ChangeScheduler& scheduler;
    std::vector<ChangeParticipant*> participants;
  };
  // Loads, plans, prepares and commits; `result()` is set at once when the
  // change is refused. Runs on the control thread (the load takes the time
  // it takes; `cancel` stops it between its stages when the PLC stops).
  ChangeRunner(const ChangeRequest& request, Setup setup, const std::atomic<bool>* cancel = nullptr);
  ~ChangeRunner();

  // Steps a committed change: true once it is complete (every task
  // switched and every participant told). Call it every few milliseconds.
  bool poll();
  // The outcome, once there is one to give: at once for a refusal, at
  // completion, or when a task is late for its switch by more than a second
  // (then the change goes on and completes when that task gets there).
  const std::optional<ChangeResult>& result() const { return result_; }
  bool committed() const {
    return tx_ && (tx_->phase() == ChangePhase::Committed || tx_->phase() == ChangePhase::Complete);
  }
  bool complete() const { return tx_ && tx_->phase() == ChangePhase::Complete; }
  // Phase Committed: the old program still runs in some task.
  Transaction* transaction() { return tx_.get(); }
  // The new program, for the PLC to own once the change is complete.
  std::unique_ptr<Program> take_new_program();
  // The project file the change loaded: after a committed load or rollback,
  // what the instance's `reload` (and SIGHUP) reloads from then on.
  const std::string& project_file() const { return project_file_; }

 private:
  void refuse(int status, std::string summary, std::vector<std::string> lines = {});
  ChangeResult accepted_result(bool complete);

  std::unique_ptr<Transaction> tx_;
  StoreLink* store_ = nullptr;
  ChangeScheduler* scheduler_ = nullptr;
  std::string what_;
  std::string project_file_;
  std::int64_t give_up_ns_ = 0;
  std::optional<ChangeResult> result_;
  std::string hash_;
};

}  // namespace syncplc::plc
