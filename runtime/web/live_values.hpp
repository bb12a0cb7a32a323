// The live values of a list of references, one tick at a time: what a live
// stream sends (GET /stream, a subscription's stream; docs/http-api.md,
// "Live values"). Each reference is resolved once per program (again after
// an online change); one that does not resolve, or that the reader may not
// see, is answered in `errors` for itself while the others go on.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "runtime/core/program.hpp"
#include "runtime/web/read_access.hpp"
#include "runtime/web/value_quality.hpp"

namespace syncplc::web {

// The logical time now on the program's time axis (the tasks' releases),
// -1 when no scheduler runs it in real time.
std::int64_t logical_now_ns(const Program& p);

// What a reference is, for a subscriber: {"task", "period_ns", "type",
// "length"} or {"error": why} (unknown, or hmi: none for this reader;
// `hidden` null: the reader sees everything).
nlohmann::json describe_ref(const Program& p, const HiddenCells* hidden, const std::string& ref);

class LiveRefs {
 public:
  // Replaces the list; resolved at the next tick.
  void set_refs(std::vector<std::string> refs);
  const std::vector<std::string>& refs() const { return refs_; }

  // With the program held (PlcHost::with_program): one tick's data,
  //   {"now_ns", "values": {ref: value}, "forced": {ref: bool},
  //    "quality": {ref: {"q", "scan_ns", "age_ns"}}, "errors"?: {ref: why}}
  // A pin whose monitoring is only starting is left out of this tick.
  // `generation`: PlcHost::program_generation(); `hidden`: what this reader
  // may not see (null: everything).
  nlohmann::json tick(Program& p, std::uint64_t generation, const HiddenCells* hidden);

 private:
  struct Entry {
    std::optional<ValueSource> source;
    std::string error;
  };
  void resolve(const Program& p, const HiddenCells* hidden);

  std::vector<std::string> refs_;
  std::vector<Entry> entries_;
  std::uint64_t generation_ = 0;
  bool resolved_ = false;
};

}  // namespace syncplc::web
