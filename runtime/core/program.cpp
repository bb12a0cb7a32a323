#include "runtime/core/program.hpp"

#include <charconv>

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

std::optional<CellRef> Program::resolve(const std::string& ref, std::string* error) const {
  auto fail = [&](const std::string& why) -> std::optional<CellRef> {
    if (error) *error = why;
    return std::nullopt;
  };
  std::string base = ref;
  std::optional<std::int64_t> element;
  if (auto lb = ref.find('['); lb != std::string::npos) {
    if (ref.back() != ']') return fail("bad element reference '" + ref + "'");
    std::string num = ref.substr(lb + 1, ref.size() - lb - 2);
    std::int64_t e = 0;
    auto [p, ec] = std::from_chars(num.data(), num.data() + num.size(), e);
    if (ec != std::errc() || p != num.data() + num.size()) return fail("bad array index in '" + ref + "'");
    element = e;
    base = ref.substr(0, lb);
  }
  CellRef r;
  if (auto dot = base.find('.'); dot != std::string::npos) {
    std::string inst = base.substr(0, dot), pin = base.substr(dot + 1);
    auto it = instances.find(inst);
    if (it == instances.end()) return fail("no block instance '" + inst + "'");
    const auto& bi = tasks[it->second.first]->blocks[it->second.second];
    int p = bi.type->pin_index(pin);
    if (p < 0) return fail("block " + inst + " (" + bi.type->name + ") has no pin '" + pin + "'");
    const auto& decl = bi.type->pins[static_cast<std::size_t>(p)];
    r.task = it->second.first;
    r.cell = bi.pin_cell[static_cast<std::size_t>(p)];
    r.type = decl.cls == TypeClass::Exact ? decl.type : bi.datatype;
    r.length = p < static_cast<int>(bi.pin_length.size()) ? bi.pin_length[static_cast<std::size_t>(p)] : 1;
    if (element) {
      if (!decl.is_array()) return fail("pin " + base + " is not an array");
      *element -= 1;  // array pins are ARRAY[1..n]
    }
  } else {
    const Tag* t = find_tag(base);
    if (!t) return fail("no tag '" + base + "'");
    r.task = t->owner;
    r.cell = t->cell;
    r.type = t->type;
    r.length = t->length;
    if (element) *element -= t->array_lower;
  }
  if (element) {
    if (*element < 0 || *element >= r.length) return fail("index out of range in '" + ref + "'");
    r.cell += static_cast<std::uint32_t>(*element);
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

}  // namespace syncplc
