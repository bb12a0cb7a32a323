// The loader's Structured Text stage (read_st.hpp).
#include "runtime/project/read_st.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "runtime/core/closest_name.hpp"
#include "runtime/project/stages.hpp"
#include "runtime/st/vm/block_signatures.hpp"
#include "runtime/st/vm/codegen.hpp"
#include "runtime/st/vm/st_block.hpp"
#include "runtime/st/vm/vm.hpp"

namespace syncplc {

namespace {

// An ST file larger than this is refused (a 10,000-line source is ~400 KB).
constexpr std::uintmax_t kMaxSourceBytes = 16u << 20;

void report(const st::StDiagnostics& d, Diagnostics& diags) {
  for (const auto& x : d.list())
    if (x.severity == st::StDiagnostic::Severity::Error) diags.error(x.loc, x.message);
}

}  // namespace

std::shared_ptr<StProject> read_st_sources(const ConfigNode* sources, const BlockRegistry& base, bool native,
                                           Diagnostics& diags, std::vector<store::SourceFile>* read) {
  auto out = std::make_shared<StProject>();
  out->blocks = std::make_unique<BlockRegistry>(&base);
  if (!sources) return out;
  std::vector<const ConfigNode*> files;
  if (sources->is_scalar()) files.push_back(sources);
  else if (sources->is_list())
    for (const auto& i : sources->items) files.push_back(&i);
  else {
    diags.error(sources->loc, "sources: a file name or a list of ST file names");
    return out;
  }
  auto unit = std::make_shared<st::vm::StUnit>();
  bool ok = true;
  for (const ConfigNode* f : files) {
    if (!f->is_scalar() || f->scalar.empty()) {
      diags.error(f->loc, "sources: expected a file name");
      ok = false;
      continue;
    }
    // Relative to the file that lists it (an include: may list its own).
    const std::filesystem::path path = std::filesystem::path(f->loc.file.str()).parent_path() / f->scalar;
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) {
      diags.error(f->loc, fmt::format("sources: cannot read '{}': {}", f->scalar, ec.message()));
      out->unreadable = true;
      ok = false;
      continue;
    }
    if (size > kMaxSourceBytes) {
      diags.error(f->loc, fmt::format("sources: '{}' is {} bytes; an ST file may have at most {}", f->scalar, size,
                                      kMaxSourceBytes));
      ok = false;
      continue;
    }
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    if (!in.good() && !in.eof()) {
      diags.error(f->loc, fmt::format("sources: cannot read '{}'", f->scalar));
      ok = false;
      continue;
    }
    const std::string body = text.str();
    if (read) read->push_back({path.string(), body});
    unit->parsed.push_back(std::make_unique<st::ParseResult>(st::parse(body, SourceFile(path.string()))));
    report(unit->parsed.back()->diagnostics, diags);
    for (const auto& pou : unit->parsed.back()->unit.pous)
      if (pou.kind != st::PouKind::Function) out->declared.insert(pou.name);
    ok = ok && unit->parsed.back()->ok();
  }
  out->failed = true;  // until the module is made
  if (!ok) return out;
  std::vector<const st::CompilationUnit*> units;
  for (const auto& p : unit->parsed) units.push_back(&p->unit);
  unit->checked = st::check(units, st::vm::block_signatures(base));
  report(unit->checked.diagnostics, diags);
  if (!unit->checked.ok()) return out;
  for (const auto& g : unit->checked.globals)
    diags.error(g->loc, fmt::format("VAR_GLOBAL {}: the project's tags are the global variables (declare it in "
                                    "tags: and reach it with VAR_EXTERNAL)",
                                    g->name));
  st::StDiagnostics gen;
  {
    std::unique_ptr<st::vm::Module> m = st::vm::compile(unit->checked, &base, gen);
    if (m && !native) st::vm::set_engine(*m, st::vm::Engine::Interpreter);
    unit->module = std::move(m);
  }
  report(gen, diags);
  if (!unit->module) return out;
  out->unit = unit;
  out->failed = false;
  for (std::uint32_t k = 0; k < unit->module->pous.size(); ++k) {
    const st::vm::CompiledPou& p = unit->module->pous[k];
    if (p.kind == st::PouKind::Function) continue;
    std::string why;
    auto type = st::vm::st_block_type(unit, k, &why);
    const st::PouInfo* info = unit->checked.pou(p.name);
    const SourceLoc loc = info && info->pou ? info->pou->loc : SourceLoc{};
    if (!type) {
      diags.error(loc, why);
      continue;
    }
    try {
      out->blocks->add(std::move(*type));
    } catch (const std::logic_error& e) {
      diags.error(loc, fmt::format("{} {}: {}", p.kind == st::PouKind::Program ? "PROGRAM" : "FUNCTION_BLOCK", p.name,
                                   base.find(p.name) ? "a built-in block has this name" : e.what()));
    }
  }
  return out;
}

void read_programs(const ConfigNode& n, const StProject& st, Declarations& p, Diagnostics& diags) {
  if (!n.is_list()) {
    diags.error(n.loc, "programs: expected a list of {name, type, task}");
    return;
  }
  for (const auto& b : n.items) {
    if (!b.is_map()) {
      diags.error(b.loc, "a program instance is a map {name, type, task}");
      continue;
    }
    InstanceDecl in;
    in.loc = b.loc;
    bool ok = true;
    const ConfigNode* task = nullptr;
    for (const auto& [k, v] : b.map) {
      if (k == "name") {
        in.name = v.scalar;
        if (!is_identifier(v.scalar)) {
          diags.error(v.loc, "program name '" + v.scalar + "' is not an identifier");
          ok = false;
        } else if (p.names.count(v.scalar)) {
          diags.error(v.loc, "duplicate name '" + v.scalar + "' (first defined at " + p.names[v.scalar].text() + ")");
          ok = false;
        } else {
          p.names[v.scalar] = v.loc;
        }
      } else if (k == "type") {
        in.type = st.blocks->find(v.scalar);
        if (!in.type && st.declares(v.scalar)) {
          ok = false;  // its source has errors, reported there
        } else if (in.type && in.type->category == "Structured Text programs" && !in.type->not_instanceable.empty()) {
          diags.error(v.loc, in.type->not_instanceable);
          in.type = nullptr;
          ok = false;
        } else if (!in.type || in.type->category != "Structured Text programs") {
          std::vector<std::string_view> names;
          for (const auto* t : st.blocks->all())
            if (t->category == "Structured Text programs") names.push_back(t->name);
          const std::string best = closest_name(v.scalar, names);
          diags.error(v.loc, fmt::format("no PROGRAM '{}' in the sources{}", v.scalar,
                                         best.empty() ? "" : " (did you mean " + best + "?)"));
          in.type = nullptr;
          ok = false;
        }
      } else if (k == "task") {
        task = &v;
      } else if (k == "description") {
      } else {
        diags.error(v.loc, "unknown key '" + k + "' in a program instance (name, type, task, description)");
      }
    }
    if (in.name.empty()) {
      diags.error(b.loc, "program instance without a name");
      ok = false;
    }
    if (!b.find("type") && ok) {
      diags.error(b.loc, "program instance " + in.name + " has no type");
      ok = false;
    }
    if (!task) {
      if (p.tasks.size() == 1) in.task = 0;
      else {
        diags.error(b.loc, "program instance " + in.name + " has no task");
        ok = false;
      }
    } else if ((in.task = p.task_index(task->scalar)) < 0) {
      diags.error(task->loc, "unknown task '" + task->scalar + "'");
      ok = false;
    }
    if (!ok || !in.type) {
      if (!in.name.empty()) p.failed_names.insert(in.name);
      continue;
    }
    in.source.assign(in.type->pins.size(), -1);
    in.pin_length.assign(in.type->pins.size(), 1);
    // VAR_EXTERNAL X : AXIS_REF names the MC_AXIS instance X (check_links
    // checks it, at the declaration).
    if (!in.type->links.empty() && st.unit)
      if (const int pou = st.unit->module->find(in.type->name); pou >= 0)
        for (const st::vm::StExternal& e : st::vm::st_externals(*st.unit, static_cast<std::uint32_t>(pou)))
          if (const int l = in.type->link_index(e.name); l >= 0) in.links.push_back({l, 0, e.name, e.loc, -1});
    mark_st_retain(in);
    p.instance_by_name.emplace(in.name, static_cast<int>(p.instances.size()));
    p.instances.push_back(std::move(in));
  }
}

void mark_st_retain(InstanceDecl& in) {
  if (!in.type) return;
  for (const auto& leaf : in.type->variable_leaves) {
    if (leaf.retain && !in.retain) {
      in.retain = true;
      in.retain_loc = in.loc;
    }
    if (leaf.persistent) in.persistent = true;
  }
}

void wire_externals(const StProject& st, Declarations& p, Diagnostics& diags) {
  if (!st.unit) return;
  const st::vm::Module& m = *st.unit->module;
  for (const InstanceDecl& in : p.instances) {
    if (!in.type || in.type->category.rfind("Structured Text", 0) != 0) continue;
    const int pou = m.find(in.type->name);
    if (pou < 0) continue;
    for (const st::vm::StExternal& e : st::vm::st_externals(*st.unit, static_cast<std::uint32_t>(pou))) {
      if (!e.type->ref_target.empty()) continue;  // an AXIS_REF: a link, not a tag
      const int tag = p.tag_index(e.name);
      if (tag < 0) {
        std::vector<std::string_view> names;
        for (const auto& t : p.tags) names.push_back(t.tag.name);
        const std::string best = closest_name(e.name, names);
        diags.error(e.loc, fmt::format("VAR_EXTERNAL {} of {} (instance {}): no tag '{}' in the project{}", e.name,
                                       in.type->name, in.name, e.name,
                                       best.empty() ? "" : " (did you mean " + best + "?)"));
        continue;
      }
      const Tag& t = p.tags[static_cast<std::size_t>(tag)].tag;
      const bool array = t.length > 1 || t.is_array;
      // The same elementary type (an enumeration or subrange: its base type);
      // an array tag: ARRAY[lower..upper] OF it with the tag's bounds.
      auto same_elem = [&](const st::Type* x) {
        return (x->is_elem() || x->kind == st::Type::Kind::Subrange || x->kind == st::Type::Kind::Enum) &&
               st::elem_name(x->elem) == type_name(t.type);
      };
      const bool same = array ? e.type->kind == st::Type::Kind::Array && e.type->dims.size() == 1 &&
                                    e.type->dims[0].low == t.array_lower &&
                                    e.type->dims[0].count() == static_cast<std::int64_t>(t.length) &&
                                    same_elem(e.type->element)
                              : same_elem(e.type);
      if (!same) {
        diags.error(e.loc, fmt::format("VAR_EXTERNAL {} : {} of {} does not match tag {} : {}", e.name, e.type->name,
                                       in.type->name, e.name,
                                       array ? fmt::format("ARRAY[{}..{}] OF {}", t.array_lower,
                                                           t.array_lower + static_cast<std::int64_t>(t.length) - 1,
                                                           type_name(t.type))
                                             : std::string(type_name(t.type))));
        continue;
      }
      p.connections.push_back({e.name, in.name + "." + e.name + st::vm::kExternalReadSuffix, e.loc, e.loc, e.loc});
      if (e.written) {
        if (e.constant) continue;
        p.connections.push_back({in.name + "." + e.name, e.name, e.loc, e.loc, e.loc});
      }
    }
  }
}

StSummary summarize_st(const StProject& st, bool native_asked) {
  StSummary s;
  s.native_asked = native_asked;
  if (!st.unit || !st.unit->module) return s;
  s.files = st.unit->parsed.size();
  s.pous = st.unit->module->pous.size();
  s.native_pous = st::vm::native_pous(*st.unit->module);
  s.register_loops = st::vm::native_register_loops(*st.unit->module);
  return s;
}

}  // namespace syncplc
