#include "runtime/core/program.hpp"

#include <algorithm>

#include "runtime/core/reference.hpp"

namespace syncplc {

std::string_view hmi_access_name(HmiAccess a) {
  switch (a) {
    case HmiAccess::None: return "none";
    case HmiAccess::Read: return "read";
    case HmiAccess::ReadWrite: return "readwrite";
  }
  return "?";
}

const Tag* Program::find_tag(const std::string& n) const {
  for (const auto& t : tags)
    if (t.name == n) return &t;
  return nullptr;
}

int Program::find_task(const std::string& n) const {
  for (std::size_t i = 0; i < tasks.size(); ++i)
    if (tasks[i]->config().name == n) return static_cast<int>(i);
  return -1;
}

int Program::find_driver(const std::string& n) const {
  for (std::size_t i = 0; i < drivers.size(); ++i)
    if (drivers[i].driver->name() == n) return static_cast<int>(i);
  return -1;
}

std::optional<CellRef> Program::resolve_variable(const std::string& text, bool* names_one, std::string* error,
                                                 BlockTypeInfo::Variable* info) const {
  *names_one = false;
  const auto dot = text.find('.');
  if (dot == std::string::npos) return std::nullopt;
  const auto it = instances.find(text.substr(0, dot));
  if (it == instances.end()) return std::nullopt;
  const auto& bi = tasks[it->second.first]->blocks[it->second.second];
  const std::string rest = text.substr(dot + 1);
  if (!bi.type->names_variable(rest)) return std::nullopt;
  std::string why;
  const auto v = bi.type->variable(rest, &why);
  // Not a variable after all (ENO, a VAR_EXTERNAL's pin): a pin.
  if (!v && bi.type->pin_index(rest.substr(0, rest.find_first_of(".["))) >= 0) return std::nullopt;
  *names_one = true;
  if (!v) {
    if (error) *error = it->first + "." + rest + ": " + why;
    return std::nullopt;
  }
  if (info) *info = *v;
  CellRef r;
  r.task = it->second.first;
  r.cell = bi.pin_cell[static_cast<std::size_t>(bi.type->variables_pin)] + v->element;
  r.type = v->type;
  r.length = 1;
  return r;
}

std::optional<CellRef> Program::resolve(const std::string& text, std::string* error) const {
  auto fail = [&](const std::string& why) -> std::optional<CellRef> {
    if (error) *error = why;
    return std::nullopt;
  };
  std::string why;
  // instance.path of a block with variables (an ST instance's, "p.fb.q", "p.arr[3]").
  bool variable = false;
  if (auto v = resolve_variable(text, &variable, &why)) return v;
  if (variable) return fail(why);
  auto ref = parse_reference(text, &why);
  if (!ref) return fail(why);
  CellRef r;
  std::int64_t lower = 0;
  if (ref->dotted()) {
    auto it = instances.find(ref->owner);
    if (it == instances.end()) return fail(unknown_instance_message(ref->owner));
    const auto& bi = tasks[it->second.first]->blocks[it->second.second];
    int p = bi.type->pin_index(ref->member);
    if (p < 0) return fail(no_pin_message(ref->owner, *bi.type, ref->member));
    const auto& decl = bi.type->pins[static_cast<std::size_t>(p)];
    r.task = it->second.first;
    r.cell = bi.pin_cell[static_cast<std::size_t>(p)];
    r.type = decl.cls == TypeClass::Exact ? decl.type : bi.datatype;
    r.length = p < static_cast<int>(bi.pin_length.size()) ? bi.pin_length[static_cast<std::size_t>(p)] : 1;
    if (ref->index && !decl.is_array()) return fail("pin " + ref->base + " is not an array");
    lower = 1;  // array pins are ARRAY[1..n]
  } else {
    const Tag* t = find_tag(ref->base);
    if (!t) return fail(unknown_tag_message(ref->base));
    r.task = t->owner;
    r.cell = t->cell;
    r.type = t->type;
    r.length = t->length;
    if (ref->index && !t->is_array) return fail("tag " + ref->base + " is not an array");
    lower = t->array_lower;
  }
  if (ref->index) {
    auto e = element_of(*ref, lower, r.length, &why);
    if (!e) return fail(why);
    r.cell += *e;
    r.length = 1;
  }
  return r;
}

void Program::read_tag(const Tag& tag, Cell* out) const {
  tasks[tag.owner]->read_published(tag.cell, tag.length, out);
}

bool Program::write_tag(const Tag& tag, std::uint32_t element, const Cell* values, std::uint32_t count) const {
  // Written so that no sum can wrap around: element and count come from outside (HMI, Modbus).
  if (count == 0 || count > 4096 || element >= tag.length || count > tag.length - element) return false;
  std::vector<QueuedWrite> w(count);
  for (std::uint32_t i = 0; i < count; ++i) w[i] = QueuedWrite{tag.cell + element + i, values[i]};
  return tasks[tag.owner]->enqueue(w.data(), count);
}

bool Program::open_drivers(std::string* error) {
  for (std::size_t i = 0; i < drivers.size(); ++i) {
    std::string err;
    if (!drivers[i].driver->open(&err)) {
      for (std::size_t j = 0; j < i; ++j) drivers[j].driver->close();
      if (error) *error = "driver " + drivers[i].driver->name() + ": " + err;
      return false;
    }
  }
  return true;
}

void Program::close_drivers() {
  for (auto& d : drivers) d.driver->close();
}

void Program::stop_drivers() {
  for (auto& d : drivers) {
    const std::vector<SafeOutput> outputs = safe_outputs(d);
    d.driver->stop_outputs(outputs.data(), outputs.size());
    d.driver->close();
  }
}

std::vector<SafeOutput> Program::safe_outputs(const DriverBinding& b) const {
  std::vector<SafeOutput> out;
  if (!b.driver) return out;
  const auto& channels = b.driver->channels();
  for (std::size_t ch = 0; ch < channels.size() && ch < b.bound_tags.size(); ++ch) {
    if (channels[ch].dir != PinDir::Out || b.bound_tags[ch].empty()) continue;
    const Tag* tag = find_tag(b.bound_tags[ch]);
    if (!tag) continue;
    const std::size_t n = std::min<std::size_t>(tag->safe.size(), channels[ch].length);
    for (std::size_t k = 0; k < n; ++k)
      out.push_back(SafeOutput{static_cast<int>(ch), static_cast<std::uint32_t>(k), tag->safe[k]});
  }
  return out;
}

}  // namespace syncplc
