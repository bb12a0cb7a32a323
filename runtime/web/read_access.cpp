#include "runtime/web/read_access.hpp"

namespace syncplc::web {

bool sees_everything(const std::optional<Session>& s) { return s && role_allows(s->role, Role::Engineer); }

HiddenCells::HiddenCells(const Program& p) {
  hidden_.resize(p.tasks.size());
  for (std::size_t t = 0; t < p.tasks.size(); ++t) hidden_[t].assign(p.tasks[t]->image_cells(), false);
  auto any = [&](std::size_t t, std::uint32_t cell, std::uint32_t n) {
    const auto& h = hidden_[t];
    for (std::uint32_t k = 0; k < n && cell + k < h.size(); ++k)
      if (h[cell + k]) return true;
    return false;
  };
  // Marks the n cells at `cell` of task t; true when one was not marked yet.
  auto mark = [&](std::size_t t, std::uint32_t cell, std::uint32_t n) {
    bool changed = false;
    auto& h = hidden_[t];
    for (std::uint32_t k = 0; k < n && cell + k < h.size(); ++k)
      if (!h[cell + k]) h[cell + k] = changed = true;
    return changed;
  };
  // An ST instance holds each input and output twice: in its pin and in
  // its variables (the frame the code runs on): hidden together.
  struct Twin {
    std::size_t task;
    std::uint32_t pin, variable;
  };
  std::vector<Twin> twins;
  for (std::size_t t = 0; t < p.tasks.size(); ++t)
    for (const BlockInstance& b : p.tasks[t]->blocks) {
      if (b.type->variables_pin < 0 || !b.type->variable) continue;
      const std::uint32_t base = b.pin_cell[static_cast<std::size_t>(b.type->variables_pin)];
      for (std::size_t q = 0; q < b.type->pins.size(); ++q) {
        const PinDecl& d = b.type->pins[q];
        if (d.name.empty() || d.name.front() == '(' || d.is_array()) continue;
        std::string why;
        if (const auto v = b.type->variable(d.name, &why)) twins.push_back({t, b.pin_cell[q], base + v->element});
      }
    }
  bool any_hidden = false;
  for (const Tag& tag : p.tags)
    if (tag.hmi == HmiAccess::None && tag.owner < hidden_.size()) any_hidden |= mark(tag.owner, tag.cell, tag.length);
  // Along the copies until nothing changes: each round marks at least one
  // more cell, so it ends.
  for (bool changed = any_hidden; changed;) {
    changed = false;
    for (std::size_t t = 0; t < p.tasks.size(); ++t) {
      const Task& task = *p.tasks[t];
      for (const Inbound& ib : task.inbound)  // a tag read by another task: its copy there
        for (const CellCopy& c : ib.copies)
          if (ib.producer < hidden_.size() && any(ib.producer, c.src, c.n)) changed |= mark(t, c.dst, c.n);
      for (const Twin& w : twins)
        if (w.task == t) {
          if (any(t, w.pin, 1)) changed |= mark(t, w.variable, 1);
          if (any(t, w.variable, 1)) changed |= mark(t, w.pin, 1);
        }
      for (const BlockInstance& b : task.blocks) {
        for (const CellCopy& c : b.copy_in)  // tag or pin -> input pin
          if (any(t, c.src, c.n)) changed |= mark(t, c.dst, c.n);
        for (const CellCopy& c : b.copy_out)  // output pin -> a hidden tag: the pin shows the tag's value
          if (any(t, c.dst, c.n)) changed |= mark(t, c.src, c.n);
      }
    }
  }
}

bool HiddenCells::hides(const CellRef& r) const {
  if (r.task >= hidden_.size()) return false;
  const auto& h = hidden_[r.task];
  for (std::uint32_t k = 0; k < r.length && r.cell + k < h.size(); ++k)
    if (h[r.cell + k]) return true;
  return false;
}

std::shared_ptr<const HiddenCells> HiddenCellsCache::get(const Program& p, std::uint64_t generation) {
  std::lock_guard lock(mutex_);
  if (!cells_ || program_ != &p || generation_ != generation) {
    cells_ = std::make_shared<const HiddenCells>(p);
    program_ = &p;
    generation_ = generation;
  }
  return cells_;
}

std::string hidden_reason(const std::string& ref) {
  return "'" + ref + "' is not shown outside the PLC (hmi: none); an engineer sees it";
}

std::string without_dirs(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  std::size_t i = 0;
  while (i < text.size()) {
    const bool starts = text[i] == '/' && (i == 0 || text[i - 1] == ' ' || text[i - 1] == '(' || text[i - 1] == '\'' ||
                                           text[i - 1] == '"' || text[i - 1] == '=' || text[i - 1] == '\n');
    if (!starts) {
      out += text[i++];
      continue;
    }
    // The path runs to a space, quote, bracket or ':' (line:col follows).
    std::size_t end = i;
    while (end < text.size() && text[end] != ' ' && text[end] != '\'' && text[end] != '"' && text[end] != ')' &&
           text[end] != ':' && text[end] != ',' && text[end] != '\n')
      ++end;
    const std::string_view path = text.substr(i, end - i);
    const std::size_t slash = path.find_last_of('/');
    out += path.substr(slash + 1);
    i = end;
  }
  return out;
}

void hide_paths(nlohmann::json& runtime) {
  runtime.erase("project_file");
  if (runtime.contains("store") && runtime["store"].is_object() && runtime["store"].contains("detail") &&
      runtime["store"]["detail"].is_string())
    runtime["store"]["detail"] = without_dirs(runtime["store"]["detail"].get<std::string>());
}

void hide_pins(nlohmann::json& instance, const InstanceInfo& b, const HiddenCells& hidden) {
  auto hide = [&](const char* key, const auto& items) {
    if (!instance.contains(key) || !instance[key].is_array()) return;
    auto& shown = instance[key];
    for (std::size_t i = 0; i < items.size() && i < shown.size(); ++i)
      if (hidden.hides(items[i].cell)) {
        shown[i]["value"] = nullptr;
        shown[i]["hidden"] = true;
      }
  };
  hide("pins", b.pins);
  hide("variables", b.variables);
}

}  // namespace syncplc::web
