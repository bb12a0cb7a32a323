#include "runtime/store/historian.hpp"

#include <SQLiteCpp/Statement.h>
#include <SQLiteCpp/Transaction.h>

#include <cmath>

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/store/event_log.hpp"
#include "runtime/store/trend_retention.hpp"

namespace syncplc::store {
namespace {

// Whether a bucket moved more than the deadband from the last stored mean:
// its min and max are compared, so a spike beyond the band is stored.
bool passes_deadband(const TrendBucket& b, double deadband, const std::optional<double>& last) {
  if (!last || deadband <= 0) return true;
  return std::fabs(b.min - *last) > deadband || std::fabs(b.max - *last) > deadband;
}

}  // namespace

Historian::Historian(Program& p, const StoreSettings& s) : settings_(s), wall_(wall_now_ns) { served_ = take_series(p, s); }

Historian::Feed Historian::take_series(Program& p, const StoreSettings& s) {
  Feed f;
  f.program = &p;
  for (auto& ts : trend_series(p, s)) {
    std::size_t i = 0;
    while (i < series_.size() && series_[i].spec.label != ts.label) ++i;
    if (i == series_.size()) series_.push_back(Series{});
    if (series_[i].spec.type != ts.type || series_[i].spec.rate_ns != ts.rate_ns || series_[i].spec.unit != ts.unit ||
        series_[i].spec.deadband != ts.deadband || series_[i].id == 0)
      series_changed_ = true;
    f.rate_ns.push_back(ts.rate_ns);
    series_[i].spec = std::move(ts);
    f.active.push_back(static_cast<std::uint32_t>(i));
  }
  f.seen_dropped.assign(p.tasks.size(), 0);
  for (std::size_t t = 0; t < p.tasks.size(); ++t) f.seen_dropped[t] = p.tasks[t]->trends.dropped();
  return f;
}

bool Historian::prepare(Database& db, std::string* error) {
  if (!ensure_trend_schema(db.sql(), error) || !RetentionClock::prepare(db.sql(), error)) return false;
  register_series(db.sql());
  return true;
}

void Historian::register_series(SQLite::Database& db) {
  if (!series_changed_) return;
  SQLite::Transaction tr(db);
  SQLite::Statement up(db,
                       "INSERT INTO trend_series (label, tag, element, type, unit, rate_ns, deadband) "
                       "VALUES (?, ?, ?, ?, ?, ?, ?) ON CONFLICT (label) DO UPDATE SET tag = excluded.tag, "
                       "element = excluded.element, type = excluded.type, unit = excluded.unit, "
                       "rate_ns = excluded.rate_ns, deadband = excluded.deadband RETURNING id");
  for (auto& s : series_) {
    up.reset();
    up.bind(1, s.spec.label);
    up.bind(2, s.spec.tag);
    up.bind(3, s.spec.element);
    up.bind(4, std::string(type_name(s.spec.type)));
    up.bind(5, s.spec.unit);
    up.bind(6, s.spec.rate_ns);
    up.bind(7, s.spec.deadband);
    if (up.executeStep()) s.id = up.getColumn(0).getInt64();  // RETURNING: the row is written at the first step
  }
  up.reset();  // no statement in progress at the commit
  tr.commit();
  series_changed_ = false;
}

void Historian::drain() {
  for (auto& f : previous_) drain(f);  // older buckets first
  drain(served_);
}

void Historian::drain(Feed& f) {
  for (std::size_t t = 0; t < f.program->tasks.size(); ++t) {
    TrendFold& fold = f.program->tasks[t]->trends;
    TrendBucket b;
    while (fold.pop(b)) {
      if (queue_.size() >= kMaxQueued) {
        lost_.fetch_add(1, std::memory_order_relaxed);  // the database refused for long: what comes now is lost, the queue (and its order) stays
        continue;
      }
      queue_.push_back(Queued{f.active[b.series], f.rate_ns[b.series], b});
    }
    const std::uint64_t dropped = fold.dropped();
    lost_.fetch_add(dropped - f.seen_dropped[t], std::memory_order_relaxed);
    f.seen_dropped[t] = dropped;
  }
}

void Historian::store_queue(SQLite::Database& db) {
  register_series(db);
  SQLite::Transaction tr(db);
  SQLite::Statement ins(db,
                        "INSERT INTO trend_point (series, level, t, span, min, max, mean, count) "
                        "VALUES (?, 0, ?, ?, ?, ?, ?, ?) ON CONFLICT (series, level, t) DO UPDATE SET "
                        "min = min(min, excluded.min), max = max(max, excluded.max), "
                        "mean = (mean * count + excluded.mean * excluded.count) / (count + excluded.count), "
                        "count = count + excluded.count");
  // The deadband state moves only when the transaction commits.
  std::vector<std::optional<double>> last(series_.size());
  for (std::size_t i = 0; i < series_.size(); ++i) last[i] = series_[i].last_stored;
  std::uint64_t n = 0;
  const std::size_t batch = queue_.size();
  for (std::size_t i = 0; i < batch; ++i) {
    // A long transaction must not let the tasks' rings overflow: they are
    // emptied into the queue as it goes (what comes in waits for the next).
    if (i % kDrainEvery == kDrainEvery - 1) drain();
    const Queued& q = queue_[i];
    const Series& s = series_[q.series];
    const TrendBucket& b = q.bucket;
    if (!passes_deadband(b, s.spec.deadband, last[q.series])) continue;
    const double mean = b.sum / b.count;
    ins.reset();
    ins.bind(1, s.id);
    ins.bind(2, *time_base_ + b.index * q.rate_ns);
    ins.bind(3, q.rate_ns);
    ins.bind(4, b.min);
    ins.bind(5, b.max);
    ins.bind(6, mean);
    ins.bind(7, static_cast<std::int64_t>(b.count));
    ins.exec();
    last[q.series] = mean;
    ++n;
  }
  tr.commit();
  for (std::size_t i = 0; i < series_.size(); ++i) series_[i].last_stored = last[i];
  queue_.erase(queue_.begin(), queue_.begin() + static_cast<std::ptrdiff_t>(batch));
  stored_ += n;
}

void Historian::run(Database& db, std::int64_t now, bool final) {
  next_drain_ = now + kDrainNs;
  drain();
  if (!time_base_) {
    const std::int64_t epoch = served_.program->epoch_ns.load(std::memory_order_acquire);
    if (epoch < 0) return;  // not running in real time yet: the buckets wait in the queue
    time_base_ = epoch + (wall_() - monotonic_ns());
  }
  if (final || now >= next_commit_) {
    if (!queue_.empty()) store_queue(db.sql());
    next_commit_ = now + kCommitNs;
  }
  if (!final && now >= next_retention_) {
    std::int64_t retention_now = 0;
    {
      SQLite::Transaction tr(db.sql());
      retention_now = clock_.now(db.sql(), wall_(), now);
      tr.commit();
    }
    apply_trend_retention(db.sql(), settings_, retention_now);
    next_retention_ = now + kRetentionNs;
  }
}

void Historian::switch_program(Program& next, const StoreSettings& settings) {
  // The old tasks run on until each reaches its switch: their buckets are
  // drained, in the old numbering, until tasks_ended(old).
  previous_.push_back(std::move(served_));
  settings_ = settings;
  served_ = take_series(next, settings);
}

void Historian::tasks_ended(Program& p) {
  auto end = [&](Feed& f) {
    for (auto& t : p.tasks) t->trends.flush();  // the buckets in progress, partial as they are
    drain(f);
  };
  if (served_.program == &p) {
    end(served_);  // a clean stop: the final run stores them
    return;
  }
  for (auto it = previous_.begin(); it != previous_.end(); ++it)
    if (it->program == &p) {
      end(*it);  // an online change completed: the old program goes after this
      previous_.erase(it);
      return;
    }
}

}  // namespace syncplc::store
