#include "runtime/store/historian.hpp"

#include <SQLiteCpp/Statement.h>
#include <SQLiteCpp/Transaction.h>

#include <cmath>
#include <ctime>

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/store/trend_retention.hpp"

namespace syncplc::store {
namespace {

std::int64_t wall_now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// Whether a bucket moved more than the deadband from the last stored mean:
// its min and max are compared, so a spike beyond the band is stored.
bool passes_deadband(const TrendBucket& b, double deadband, const std::optional<double>& last) {
  if (!last || deadband <= 0) return true;
  return std::fabs(b.min - *last) > deadband || std::fabs(b.max - *last) > deadband;
}

}  // namespace

Historian::Historian(Program& p, const StoreSettings& s) : program_(&p), settings_(s) { take_series(p, s); }

void Historian::take_series(const Program& p, const StoreSettings& s) {
  active_.clear();
  for (auto& ts : trend_series(p, s)) {
    std::size_t i = 0;
    while (i < series_.size() && series_[i].spec.label != ts.label) ++i;
    if (i == series_.size()) series_.push_back(Series{});
    if (series_[i].spec.type != ts.type || series_[i].spec.rate_ns != ts.rate_ns || series_[i].spec.unit != ts.unit ||
        series_[i].spec.deadband != ts.deadband || series_[i].id == 0)
      series_changed_ = true;
    series_[i].spec = std::move(ts);
    active_.push_back(static_cast<std::uint32_t>(i));
  }
  seen_dropped_.assign(p.tasks.size(), 0);
  for (std::size_t t = 0; t < p.tasks.size(); ++t) seen_dropped_[t] = p.tasks[t]->trends.dropped();
}

bool Historian::prepare(Database& db, std::string* error) {
  if (!ensure_trend_schema(db.sql(), error)) return false;
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
  for (std::size_t t = 0; t < program_->tasks.size(); ++t) {
    TrendFold& fold = program_->tasks[t]->trends;
    TrendBucket b;
    while (fold.pop(b)) {
      if (queue_.size() >= kMaxQueued) {
        ++lost_;  // the database refused for long: what comes now is lost, the queue (and its order) stays
        continue;
      }
      queue_.push_back(Queued{active_[b.series], b});
    }
    const std::uint64_t dropped = fold.dropped();
    lost_ += dropped - seen_dropped_[t];
    seen_dropped_[t] = dropped;
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
    ins.bind(2, *time_base_ + b.index * s.spec.rate_ns);
    ins.bind(3, s.spec.rate_ns);
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
    const std::int64_t epoch = program_->epoch_ns.load(std::memory_order_acquire);
    if (epoch < 0) return;  // not running in real time yet: the buckets wait in the queue
    time_base_ = epoch + (wall_now_ns() - monotonic_ns());
  }
  if (final || now >= next_commit_) {
    if (!queue_.empty()) store_queue(db.sql());
    next_commit_ = now + kCommitNs;
  }
  if (!final && now >= next_retention_) {
    apply_trend_retention(db.sql(), settings_, wall_now_ns());
    next_retention_ = now + kRetentionNs;
  }
}

void Historian::switch_program(Program& next, const StoreSettings& settings) {
  drain();  // the old tasks' finished buckets, in the old numbering
  program_ = &next;
  settings_ = settings;
  take_series(next, settings);
}

}  // namespace syncplc::store
