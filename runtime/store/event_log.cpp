#include "runtime/store/event_log.hpp"

#include <SQLiteCpp/Statement.h>
#include <SQLiteCpp/Transaction.h>
#include <time.h>

#include <iterator>
#include <limits>

#include "runtime/store/schema.hpp"

namespace syncplc::store {
namespace {

// The age limit needs no precision finer than this; the count limit is kept
// at every write.
constexpr std::int64_t kRetentionEveryNs = 60'000'000'000;

}  // namespace

std::int64_t wall_now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

bool EventQueue::push(EventRecord r) {
  std::function<void()> notify;
  {
    std::lock_guard lk(mutex_);
    if (queued_.size() + in_flight_ >= capacity_) {
      ++dropped_;
      return false;
    }
    queued_.push_back(std::move(r));
    notify = on_push_;
  }
  if (notify) notify();
  return true;
}

std::uint64_t EventQueue::dropped() const {
  std::lock_guard lk(mutex_);
  return dropped_;
}

std::size_t EventQueue::pending() const {
  std::lock_guard lk(mutex_);
  return queued_.size() + in_flight_;
}

bool EventQueue::empty() const {
  std::lock_guard lk(mutex_);
  return queued_.empty();
}

void EventQueue::take(std::vector<EventRecord>& out) {
  std::lock_guard lk(mutex_);
  in_flight_ += queued_.size();
  out.insert(out.end(), std::make_move_iterator(queued_.begin()), std::make_move_iterator(queued_.end()));
  queued_.clear();
}

void EventQueue::settle(std::size_t n) {
  std::lock_guard lk(mutex_);
  in_flight_ -= std::min(n, in_flight_);
}

const SchemaPart& EventLog::schema() {
  static const SchemaPart part{
      "events",
      {"CREATE TABLE events ("
       " id INTEGER PRIMARY KEY AUTOINCREMENT,"
       " time_ns INTEGER NOT NULL,"   // wall time, ns since 1970 (UTC)
       " kind TEXT NOT NULL,"
       " task TEXT,"                  // NULL: no task concerned
       " scan INTEGER,"               // the task's scan count when raised; NULL: not known
       " source TEXT NOT NULL,"
       " message TEXT NOT NULL,"
       " client TEXT"                 // ip:port of the HMI for writes and refused connections
       ");"
       "CREATE INDEX events_time ON events (time_ns);"}};
  return part;
}

EventRetention retention_of(const StoreSettings& s) { return EventRetention{s.events_max_count, s.events_max_age_ns}; }

EventLog::EventLog(EventQueue& queue, EventRetention retention) : queue_(queue), retention_(retention), wall_(wall_now_ns) {}

bool EventLog::prepare(Database& db, std::string* error) {
  return ensure_schema(db.sql(), schema(), error) && RetentionClock::prepare(db.sql(), error);
}

std::int64_t EventLog::due_ns() const {
  if (!batch_.empty() || !queue_.empty()) return 0;
  return next_retention_ns_;
}

void EventLog::switch_program(Program& next, const StoreSettings& settings) {
  (void)next;
  retention_ = retention_of(settings);
  next_retention_ns_ = 0;  // the new limits apply at the next run
}

void EventLog::enforce_retention(SQLite::Database& db, std::int64_t now) {
  SQLite::Statement by_age(db, "DELETE FROM events WHERE time_ns < ?");
  by_age.bind(1, now - retention_.max_age_ns);
  by_age.exec();
  // The newest max_count rows stay (ids grow with insertion).
  SQLite::Statement by_count(db, "DELETE FROM events WHERE id <= (SELECT max(id) FROM events) - ?");
  by_count.bind(1, static_cast<std::int64_t>(std::min<std::uint64_t>(retention_.max_count,
                                                                    std::numeric_limits<std::int64_t>::max())));
  by_count.exec();
}

void EventLog::run(Database& db, std::int64_t now_ns, bool final) {
  (void)final;  // a final run writes what is queued, like any other
  queue_.take(batch_);
  SQLite::Database& sql = db.sql();
  const bool age_due = now_ns >= next_retention_ns_;
  if (batch_.empty() && !age_due) return;
  SQLite::Transaction t(sql);
  SQLite::Statement ins(sql, "INSERT INTO events (time_ns, kind, task, scan, source, message, client) "
                             "VALUES (?, ?, ?, ?, ?, ?, ?)");
  for (const auto& r : batch_) {
    ins.bind(1, r.wall_ns);
    ins.bind(2, r.kind);
    if (r.task.empty()) ins.bind(3);
    else ins.bind(3, r.task);
    if (r.scan) ins.bind(4, static_cast<std::int64_t>(*r.scan));
    else ins.bind(4);
    ins.bind(5, r.source);
    ins.bind(6, r.message);
    if (r.client.empty()) ins.bind(7);
    else ins.bind(7, r.client);
    ins.exec();
    ins.reset();
  }
  enforce_retention(sql, clock_.now(sql, wall_(), now_ns));
  t.commit();  // throws when the disk is full or the file read-only: batch_ stays for the next try
  queue_.settle(batch_.size());
  batch_.clear();
  if (age_due) next_retention_ns_ = now_ns + kRetentionEveryNs;
}

}  // namespace syncplc::store
