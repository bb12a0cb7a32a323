// The historian's retention (docs/store.md, "Retention"): raw points older
// than trend_raw_age are folded into buckets of trend_downsample (min of the
// mins, max of the maxes, count-weighted mean, summed counts; level 1), then
// everything older than trend_max_age goes, then the oldest points until the
// database's used pages take at most trend_max_size (the trends are nearly
// all of it). Each step in its own transaction.
#pragma once

#include <SQLiteCpp/Database.h>

#include <cstdint>

#include "runtime/store/store_settings.hpp"

namespace syncplc::store {

// The historian's tables (schema part "trends"; docs/store.md lists them).
bool ensure_trend_schema(SQLite::Database& db, std::string* error);

struct RetentionReport {
  std::uint64_t downsampled = 0;  // raw points folded into level-1 buckets
  std::uint64_t expired = 0;      // points older than trend_max_age deleted
  std::uint64_t trimmed = 0;      // oldest points deleted for trend_max_size
};

// `now_ns`: now by the retention clock (retention_clock.hpp), not the wall
// clock as it reads: ages count only as far as the PLC lived through them.
RetentionReport apply_trend_retention(SQLite::Database& db, const StoreSettings& s, std::int64_t now_ns);

// Bytes of the database's pages in use (page_count - freelist_count): two
// pragmas, where measuring the trend tables alone (dbstat) would read them whole.
std::uint64_t database_used_bytes(SQLite::Database& db);

}  // namespace syncplc::store
