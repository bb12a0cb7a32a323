// What a project says about the PLC's database (the `store:` section, a
// tag's `trend:` key): plain data, filled by the loader (runtime/project),
// used by the store thread's jobs. docs/store.md describes every field.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace syncplc::store {

// A tag sampled into the historian. rate_ns 0: every scan of its task.
// deadband: a sample is stored only when the value moved more than this
// since the last stored one (0: every sample); the bucket's min, max and mean
// are kept whatever the deadband, so no spike is lost.
struct TrendSpec {
  std::uint32_t tag = 0;  // index in Program::tags
  std::int64_t rate_ns = 0;
  double deadband = 0;
};

struct StoreSettings {
  bool declared = false;  // the project has a store: section
  std::string path;       // "" : --db, else the default (docs/store.md)
  // Retain and persistent values are taken from the snapshots this often,
  // and once more at a clean stop: a crash loses at most one interval.
  std::int64_t retain_interval_ns = 1'000'000'000;
  // The event log keeps at most this many events, none older than this.
  std::uint64_t events_max_count = 100'000;
  std::int64_t events_max_age_ns = 90LL * 24 * 3600 * 1'000'000'000;
  // The historian: raw points kept this long, then downsampled into buckets of
  // trend_downsample_ns (min, max, mean kept), the whole kept under
  // trend_max_age_ns and trend_max_bytes (oldest first).
  std::int64_t trend_raw_age_ns = 24LL * 3600 * 1'000'000'000;
  std::int64_t trend_downsample_ns = 60'000'000'000;
  std::int64_t trend_max_age_ns = 365LL * 24 * 3600 * 1'000'000'000;
  std::uint64_t trend_max_bytes = 1ULL << 30;
  std::vector<TrendSpec> trends;  // in tag order
  // The project store's content hash of the files this load read
  // (project_store.hpp): what retain compares to decide "the project
  // changed" (docs/store.md, "Starts"). "" when loaded from no file.
  std::string content_hash;
};

}  // namespace syncplc::store
