// `syncplc run`'s side of the HTTP server (runtime/web/plc_host.hpp): the
// running program behind one mutex that only the main thread's online
// change takes for long (the scan never takes it), the runtime's status as
// the main thread last saw it, and online changes asked for over HTTP,
// queued for the main thread, which carries them out as `syncplc reload`.
#pragma once

#include <atomic>
#include <condition_variable>
#include <deque>
#include <future>
#include <memory>
#include <mutex>
#include <string>

#include "runtime/cli/plc_store.hpp"
#include "runtime/web/plc_host.hpp"

namespace syncplc::cli {

class RunWebHost final : public web::PlcHost {
 public:
  RunWebHost(Program* program, PlcStore& store, LoadOptions options, std::string upload_dir);

  // --- HTTP threads (web::PlcHost)
  void with_program(const std::function<void(Program&)>& f) override;
  std::uint64_t program_generation() const override { return generation_.load(std::memory_order_acquire); }
  nlohmann::json runtime_status() override;
  web::ChangeOutcome change(const web::ChangeRequest& r) override;
  void record_event(const std::string& kind, const std::string& task, const std::string& message,
                    const std::string& client) override;
  std::string database_path() const override;
  std::string upload_dir() const override { return upload_dir_; }
  LoadOptions load_options() const override { return options_; }

  // --- the main thread
  // Held while the program is replaced (the online change's switch hook).
  std::unique_lock<std::mutex> hold() { return std::unique_lock(program_mutex_); }
  // With hold(): the program now running.
  void set_program(Program* p);
  // The status readers see (taken every main loop turn).
  void set_status(nlohmann::json status);
  // The project store's hash of the running program's files (GET /projects' "running").
  void set_project_hash(std::string hash);
  // The next change asked for over HTTP; false when none waits.
  bool take_change(web::ChangeRequest& r);
  // Its outcome, for the HTTP thread that waits for it.
  void finish_change(const web::ChangeOutcome& o);
  // From now on every change is refused (run is stopping); waiting ones too.
  void close();

 private:
  std::mutex program_mutex_;
  Program* program_ = nullptr;
  std::atomic<std::uint64_t> generation_{0};
  PlcStore& store_;
  LoadOptions options_;
  std::string upload_dir_;

  std::mutex status_mutex_;
  nlohmann::json status_ = nlohmann::json::object();
  std::string project_hash_;

  std::mutex changes_mutex_;
  struct Pending {
    web::ChangeRequest request;
    std::promise<web::ChangeOutcome> outcome;
  };
  std::deque<std::unique_ptr<Pending>> queued_;
  std::unique_ptr<Pending> current_;  // taken by the main thread, not yet finished
  bool closed_ = false;
};

}  // namespace syncplc::cli
