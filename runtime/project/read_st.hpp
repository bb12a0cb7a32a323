// The project's Structured Text (docs/project-format.md, "sources:" and
// "programs:"): the ST files read, parsed, checked and compiled together in
// stage 1, their FUNCTION_BLOCKs and PROGRAMs made block types beside the
// built-in ones, PROGRAM instances declared like block instances, and every
// VAR_EXTERNAL wired to the tag of its name.
#pragma once

#include <memory>
#include <set>
#include <string>
#include <vector>

#include "runtime/core/block.hpp"
#include "runtime/core/config_node.hpp"
#include "runtime/project/declarations.hpp"
#include "runtime/project/diagnostics.hpp"
#include "runtime/project/st_summary.hpp"
#include "runtime/store/source_file.hpp"

namespace syncplc {

namespace st::vm {
struct StUnit;
}

// What the ST stage gives the rest of the load: the block types (the
// built-in ones and the project's) and what they run.
struct StProject {
  std::shared_ptr<st::vm::StUnit> unit;  // null when the project has no sources (or they have errors)
  std::unique_ptr<BlockRegistry> blocks;  // the project's ST types over the base registry
  // The FUNCTION_BLOCKs and PROGRAMs the sources declare, also when they did
  // not compile: a block or program of such a type is not reported unknown
  // then (the source's own errors say what is wrong).
  std::set<std::string> declared;
  bool failed = false;
  bool unreadable = false;  // a source could not be read: any type may be in it
  bool declares(const std::string& type) const { return failed && (unreadable || declared.count(type) > 0); }
};

// Reads `sources:` (file names relative to the file that lists them), adding
// each file to `read`; every lexical, syntax, type and code-generation error
// goes to diags at its file:line:col. Always returns a registry (the base
// one's types at least).
// `native`: the module runs as native code where the machine allows
// (project: st_engine), else on the interpreter.
std::shared_ptr<StProject> read_st_sources(const ConfigNode* sources, const BlockRegistry& base, bool native,
                                           Diagnostics& diags, std::vector<store::SourceFile>* read);

// How the project's ST runs, for `syncplc check` (LoadResult::st).
StSummary summarize_st(const StProject& st, bool native_asked);

// `programs:` [{name, type, task}]: PROGRAM instances, declared as block instances.
void read_programs(const ConfigNode& n, const StProject& st, Declarations& p, Diagnostics& diags);

// An instance of an ST type with RETAIN (PERSISTENT) variables is retained
// (persistent) as `retain: true` (`persistent: true`) makes a block.
void mark_st_retain(InstanceDecl& in);

// Each ST instance's VAR_EXTERNALs: the tag of the same name (type checked)
// wired to its read pin, and its write pin to the tag when the POU writes it.
void wire_externals(const StProject& st, Declarations& p, Diagnostics& diags);

}  // namespace syncplc
