#include "runtime/plc/store_link.hpp"

#include <cstdlib>
#include <filesystem>

#include "runtime/store/historian.hpp"

namespace syncplc::plc {
namespace fs = std::filesystem;

std::string default_database_path() {
  if (const char* x = std::getenv("XDG_STATE_HOME"); x && *x == '/') return std::string(x) + "/syncplc/plc.db";
  const char* home = std::getenv("HOME");
  return std::string(home && *home ? home : "/root") + "/.local/state/syncplc/plc.db";
}

std::string database_path(const std::string& option, const store::StoreSettings& s, const std::string& project_file) {
  if (!option.empty()) return option;
  if (!s.path.empty()) {
    if (s.path == store::kMemoryDatabase || fs::path(s.path).is_absolute()) return s.path;
    return (fs::absolute(project_file).parent_path() / s.path).lexically_normal().string();
  }
  return default_database_path();
}

namespace {

// The jobs the project needs, each prepared on `db` (its tables).
bool add_jobs(store::StoreThread& st, Program& p, const LoadResult& loaded, store::StartMode start,
              std::vector<std::string>& retain_notices, std::string* error, store::ProjectsJob*& projects,
              const store::Historian*& historian) {
  auto retain = std::make_unique<store::RetainJob>(p, loaded.store, start);
  store::RetainJob& r = *retain;
  if (!st.add(std::move(retain), error)) return false;
  retain_notices = r.start_notices();
  auto h = std::make_unique<store::Historian>(p, loaded.store);
  historian = h.get();
  if (!st.add(std::move(h), error)) return false;
  auto pj = std::make_unique<store::ProjectsJob>();
  projects = pj.get();
  return st.add(std::move(pj), error);
}

}  // namespace

std::unique_ptr<StoreLink> StoreLink::open(const std::string& path, Program& p, const LoadResult& loaded,
                                         std::vector<std::string>& notices, std::string* error, store::StartMode start) {
  std::unique_ptr<StoreLink> s(new StoreLink);
  s->path_ = path;
  store::OpenReport report;
  std::string why;
  store::OpenOptions options;
  options.allow_read_only = true;
  auto db = store::Database::open(path, &report, &why, options);
  if (!db) {
    if (report.locked || report.busy) {
      *error = why;
      return nullptr;
    }
    // The PLC runs on without its memory, and says so.
    s->off_reason_ = why;
    notices.push_back("store off: " + why + "; retain values start from their initial values and nothing is recorded");
    return s;
  }
  if (report.read_only) return open_read_only(std::move(s), *db, report.read_only_reason, p, loaded, notices, error, start);
  if (!report.moved_aside.empty())
    notices.push_back("store: the database " + path + " was unreadable (" + report.problem + "); it was moved to " +
                      report.moved_aside + " and a new one started: retain values start from their initial values");
  s->thread_ = std::make_unique<store::StoreThread>(std::move(db));
  if (!add_jobs(*s->thread_, p, loaded, start, s->retain_notices_, error, s->projects_, s->historian_)) return nullptr;
  store::StoreThread* st = s->thread_.get();
  s->events_.on_push([st] { st->wake(); });
  if (!st->add(std::make_unique<store::EventLog>(s->events_, store::retention_of(loaded.store)), error)) return nullptr;
  if (!report.moved_aside.empty())
    s->record(store::EventRecord{store::wall_now_ns(), "store-moved-aside", "", std::nullopt, "store",
                                 "the database was unreadable (" + report.problem + "); moved to " + report.moved_aside +
                                     ", a new one started",
                                 ""});
  return s;
}

std::unique_ptr<StoreLink> StoreLink::open_read_only(std::unique_ptr<StoreLink> s, store::Database& db,
                                                   const std::string& reason, Program& p, const LoadResult& loaded,
                                                   std::vector<std::string>& notices, std::string* error,
                                                   store::StartMode start) {
  // No store thread: the values come back from the file as it is, and the
  // connection closes before the first scan (it leaves no file behind).
  s->read_only_reason_ = reason;
  try {
    if (!store::retain_tables_readable(db.sql(), error)) return nullptr;
    s->retain_notices_ = store::restore_retain(db.sql(), p, start, loaded.store.content_hash, /*record=*/false);
  } catch (const std::exception& e) {
    s->read_only_reason_.clear();
    s->off_reason_ = "the database " + s->path_ + " is write-protected and cannot be read: " + e.what();
    notices.push_back("store off: " + s->off_reason_ + "; retain values start from their initial values and nothing is recorded");
    return s;
  }
  notices.push_back("store READ-ONLY: the database " + s->path_ + " is write-protected (" + reason +
                    "): retained values come from it, but nothing is recorded (no events, retained values, trends "
                    "or project versions) until it is writable and run starts again");
  return s;
}

StoreLink::~StoreLink() { stop(); }

void StoreLink::start() {
  if (thread_) thread_->start();
}

void StoreLink::stop() {
  if (thread_) thread_->stop();
}

void StoreLink::switch_program(Program& next, const LoadResult& loaded) {
  if (thread_) thread_->switch_program(next, loaded.store);
}

void StoreLink::tasks_ended(Program& p) {
  if (thread_) thread_->tasks_ended(p);
}

std::uint64_t StoreLink::trend_buckets_lost() const { return historian_ ? historian_->lost() : 0; }

void StoreLink::record(store::ProjectLoad load) {
  if (!projects_) return;
  projects_->submit(std::move(load));
  thread_->wake();
}

void StoreLink::record(store::EventRecord r) {
  if (thread_) events_.push(std::move(r));
}

void StoreLink::watch_health() {
  if (!thread_) return;
  const store::StoreHealth h = thread_->health();
  if (h.fault == fault_seen_) return;
  fault_seen_ = h.fault;
  // Written when the database takes writes again, at the time it was seen.
  record(store::EventRecord{store::wall_now_ns(), h.fault ? "store-fault" : "store-ok", "", std::nullopt, "store",
                            h.fault ? "the database refuses to write: " + h.last_error + "; records wait (at most " +
                                          std::to_string(events_.capacity()) + " events)"
                                    : "the database takes writes again; waiting records written",
                            ""});
}

store::StoreHealth StoreLink::health() const {
  if (!thread_) {
    store::StoreHealth h;
    h.fault = !read_only();
    h.last_error = read_only() ? read_only_reason_ : off_reason_;
    return h;
  }
  return thread_->health();
}

}  // namespace syncplc::plc
