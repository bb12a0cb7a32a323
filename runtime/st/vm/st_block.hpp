// Compiled ST in the project: a FUNCTION_BLOCK as a block type beside the
// built-in ones (its elementary VAR_INPUT/VAR_OUTPUTs are its pins) and a
// PROGRAM as a block type without pins of its own; both reach tags through
// VAR_EXTERNAL, each one a pair of pins the loader wires to the tag of that
// name: `x_in` (the tag read at the scan's start) and `x` (written back after
// the scan, when the POU writes it). So a tag written by ST belongs to its
// task, and blocks and programs are ordered together by their data flow,
// exactly as for built-in blocks.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "runtime/core/block.hpp"
#include "runtime/st/checker.hpp"
#include "runtime/st/parser.hpp"
#include "runtime/st/vm/instance.hpp"

namespace syncplc::st::vm {

// A project's compiled Structured Text: the parsed sources, the checker's
// result and the module, kept together (each points into the one before).
struct StUnit {
  std::vector<std::unique_ptr<ParseResult>> parsed;
  CheckedProgram checked;
  std::shared_ptr<const Module> module;
};

struct StExternal {
  std::string name;
  const Type* type = nullptr;
  bool written = false;
  bool constant = false;
  SourceLoc loc;  // the first VAR_EXTERNAL declaring it
};

// The VAR_EXTERNALs an instance of POU `pou` reaches: its own and those of
// the FB instances in its frame, one per name.
std::vector<StExternal> st_externals(const StUnit& unit, std::uint32_t pou);

// The suffix of the pin through which a VAR_EXTERNAL reads its tag.
inline constexpr const char* kExternalReadSuffix = "_in";
// The array output pin that holds the instance's frame (its variables, so
// they are published, monitored, traced and forced like pins), and the
// parameter that sizes it (set by the compiler; not to be given).
inline constexpr const char* kVariablesPin = "(variables)";
inline constexpr const char* kVariablesParam = "(variable cells)";
inline constexpr const char* kCodeParam = "(code)";
// The largest frame of an instance, in cells (8 MiB).
inline constexpr std::uint32_t kMaxFrameCells = 1u << 20;

// The block type of FUNCTION_BLOCK or PROGRAM `pou`; nullopt with the
// reason when it cannot be one (a pin name twice, an external of a type a
// tag cannot have). Register it with BlockRegistry::add (ENO, guards).
std::optional<BlockTypeInfo> st_block_type(std::shared_ptr<const StUnit> unit, std::uint32_t pou, std::string* why);

}  // namespace syncplc::st::vm
