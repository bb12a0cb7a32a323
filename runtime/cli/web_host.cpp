#include "runtime/cli/web_host.hpp"

#include <signal.h>
#include <unistd.h>

#include "runtime/store/database.hpp"

namespace syncplc::cli {
namespace {

web::ChangeOutcome refused(int status, std::string why) {
  web::ChangeOutcome o;
  o.status = status;
  o.summary = std::move(why);
  return o;
}

}  // namespace

RunWebHost::RunWebHost(Program* program, PlcStore& store, LoadOptions options, std::string upload_dir)
    : program_(program), store_(store), options_(std::move(options)), upload_dir_(std::move(upload_dir)) {}

void RunWebHost::with_program(const std::function<void(Program&)>& f) {
  std::lock_guard lock(program_mutex_);
  f(*program_);
}

void RunWebHost::set_program(Program* p) {
  program_ = p;
  generation_.fetch_add(1, std::memory_order_acq_rel);
}

nlohmann::json RunWebHost::runtime_status() {
  std::lock_guard lock(status_mutex_);
  nlohmann::json j = status_;
  j["project_hash"] = project_hash_;
  return j;
}

void RunWebHost::set_project_hash(std::string hash) {
  std::lock_guard lock(status_mutex_);
  project_hash_ = std::move(hash);
}

void RunWebHost::set_status(nlohmann::json status) {
  std::lock_guard lock(status_mutex_);
  status_ = std::move(status);
}

web::ChangeOutcome RunWebHost::change(const web::ChangeRequest& r) {
  std::future<web::ChangeOutcome> done;
  {
    std::lock_guard lock(changes_mutex_);
    if (closed_) return refused(409, "the PLC is stopping: no online change now");
    if (queued_.size() >= 4) return refused(409, "other online changes are waiting; try again when they are done");
    auto p = std::make_unique<Pending>();
    p->request = r;
    done = p->outcome.get_future();
    queued_.push_back(std::move(p));
  }
  kill(getpid(), SIGUSR2);  // wakes run's main thread (it waits for signals)
  return done.get();
}

bool RunWebHost::take_change(web::ChangeRequest& r) {
  std::lock_guard lock(changes_mutex_);
  if (queued_.empty() || current_) return false;
  current_ = std::move(queued_.front());
  queued_.pop_front();
  r = current_->request;
  return true;
}

void RunWebHost::finish_change(const web::ChangeOutcome& o) {
  std::lock_guard lock(changes_mutex_);
  if (!current_) return;
  current_->outcome.set_value(o);
  current_.reset();
}

void RunWebHost::close() {
  std::lock_guard lock(changes_mutex_);
  closed_ = true;
  const auto stopping = refused(409, "the PLC stopped before the change was made; nothing was changed");
  if (current_) current_->outcome.set_value(stopping);
  current_.reset();
  for (auto& p : queued_) p->outcome.set_value(stopping);
  queued_.clear();
}

void RunWebHost::record_event(const std::string& kind, const std::string& task, const std::string& message,
                              const std::string& client) {
  store_.record(store::EventRecord{store::wall_now_ns(), kind, task, std::nullopt, "http", message, client});
}

std::string RunWebHost::database_path() const { return store_.on() ? store_.path() : std::string(); }

}  // namespace syncplc::cli
