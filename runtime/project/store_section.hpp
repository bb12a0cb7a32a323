// The store keys of a project file: the `store:` section (the database's
// path, the retain interval, the event log's and the historian's limits) and
// a tag's `trend:` key. docs/project-format.md lists them; docs/store.md says
// what they do.
#pragma once

#include <optional>

#include "runtime/core/config_node.hpp"
#include "runtime/core/program.hpp"
#include "runtime/project/diagnostics.hpp"
#include "runtime/store/store_settings.hpp"

namespace syncplc {

// Fills `out` from the `store:` section; every wrong key or value is an error at its place.
void read_store_section(const ConfigNode& n, store::StoreSettings& out, Diagnostics& d);

// A tag's `trend:`: `true` (every scan of its task), `false`, or
// {rate: 100ms, deadband: 0.5}. `tag` has its name and type read; only
// elementary numeric and BOOL tags (scalars or arrays) trend.
// Nullopt (after reporting, if wrong) when the tag is not trended.
std::optional<store::TrendSpec> read_trend(const ConfigNode& n, const Tag& tag, Diagnostics& d);

// "512MB", "1GiB", "100000" (bytes): decimal kB/MB/GB/TB or binary KiB/MiB/GiB/TiB.
std::optional<std::uint64_t> parse_byte_size(const std::string& text, std::string* error);

}  // namespace syncplc
