// Shared helpers for the IEC block tests.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <set>
#include <string>

#include "fblocks/library.hpp"
#include "runtime/core/block_harness.hpp"

namespace syncplc::iectest {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kUs = 1'000;
constexpr std::int64_t ms(std::int64_t v) { return v * kMs; }

inline const BlockRegistry& registry() { return builtin_blocks(); }

inline BlockHarness::Options opts(std::optional<IecType> dt = std::nullopt,
                                  std::optional<std::set<std::string>> connected = std::nullopt,
                                  std::int64_t period_ns = kMs) {
  BlockHarness::Options o;
  o.datatype = dt;
  o.connected = std::move(connected);
  o.period_ns = period_ns;
  return o;
}

inline std::string errors_of(const BlockHarness& h) {
  std::string s;
  for (const auto& e : h.errors()) s += e + "\n";
  return s;
}

#define ASSERT_HARNESS_OK(h) ASSERT_TRUE((h).ok()) << ::syncplc::iectest::errors_of(h)

}  // namespace syncplc::iectest
