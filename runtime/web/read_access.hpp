// What a reader of the HTTP API may see (docs/http-api.md, "Who sees what").
// A tag with `hmi: none` is the program's own: its value is not shown
// outside the PLC on any read path (values, tags, block pins, streams,
// trends, forces) to anonymous readers, viewers and operators. Nor are file
// paths (the project file, the database, a version's source). An engineer
// sees both: engineers force any tag (forcing ignores `hmi:`) and load
// projects, so hiding from them what they change would only blind them.
#pragma once

#include <nlohmann/json.hpp>

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/core/program.hpp"
#include "runtime/web/sessions.hpp"

namespace syncplc::web {

// Whether the caller sees hmi: none values and file paths: an engineer's session.
bool sees_everything(const std::optional<Session>& s);

// The cells whose values are hmi: none: those of every hmi: none tag, the
// copies of them in the tasks that read them, and every block pin wired to
// or from one of those (directly or through other pins): a pin wired to a
// hidden tag shows the tag's value. Built with the program held.
class HiddenCells {
 public:
  explicit HiddenCells(const Program& p);
  // Whether any element of `r` is hidden.
  bool hides(const CellRef& r) const;

 private:
  std::vector<std::vector<bool>> hidden_;  // per task, per image cell
};

// One HiddenCells per running program, built by the first read that needs
// it (it walks every copy of every block, so not once per request), again
// after an online change. Thread-safe.
class HiddenCellsCache {
 public:
  // `generation`: PlcHost::program_generation(), read with `p` held.
  std::shared_ptr<const HiddenCells> get(const Program& p, std::uint64_t generation);

 private:
  std::mutex mutex_;
  const Program* program_ = nullptr;
  std::uint64_t generation_ = 0;
  std::shared_ptr<const HiddenCells> cells_;
};

// "'sw' is not shown outside the PLC (hmi: none)": the refusal's text.
std::string hidden_reason(const std::string& ref);

// `text` with every absolute path cut to its last part ("/srv/plc/line.yaml:3:4"
// -> "line.yaml:3:4"): what a reader who may not see paths gets.
std::string without_dirs(std::string_view text);

// GET /status's runtime object for a reader who may not see paths: no
// project file, the store's detail without directories.
void hide_paths(nlohmann::json& runtime);

// A block instance's JSON (program_json.hpp) with its hidden pins' values
// null and marked "hidden": true.
void hide_pins(nlohmann::json& instance, const InstanceInfo& b, const HiddenCells& hidden);

}  // namespace syncplc::web
