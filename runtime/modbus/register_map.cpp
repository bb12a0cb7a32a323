#include "runtime/modbus/register_map.hpp"

#include <algorithm>
#include <cstring>
#include <iterator>
#include <map>
#include <ostream>

namespace syncplc {

namespace {

struct Range {
  ModbusTable table;
  std::uint32_t base;   // first register/coil of the area
  std::uint32_t limit;  // one past the last
  std::uint32_t per_index;  // registers per address index (%MD: 2, %ML: 4)
};

// The OpenPLC convention; nullopt when the address has no Modbus place.
std::optional<Range> convention(const DirectAddress& a) {
  using S = AddrSize;
  if (a.size == S::Bit) {
    if (a.area == Area::Input) return Range{ModbusTable::DiscreteInputs, 0, 8192, 1};
    if (a.area == Area::Output) return Range{ModbusTable::Coils, 0, 8192, 1};
    return std::nullopt;
  }
  if (a.size == S::Word) {
    if (a.area == Area::Input) return Range{ModbusTable::InputRegisters, 0, 1024, 1};
    if (a.area == Area::Output) return Range{ModbusTable::HoldingRegisters, 0, 1024, 1};
    return Range{ModbusTable::HoldingRegisters, 1024, 2048, 1};
  }
  if (a.area == Area::Memory && a.size == S::Double) return Range{ModbusTable::HoldingRegisters, 2048, 4096, 2};
  if (a.area == Area::Memory && a.size == S::Long) return Range{ModbusTable::HoldingRegisters, 4096, 8192, 4};
  return std::nullopt;
}

}  // namespace

namespace {

constexpr std::uint64_t kTableSize = 65536;  // Modbus addresses 0..65535 in each table

bool table_writable(ModbusTable t) { return t == ModbusTable::Coils || t == ModbusTable::HoldingRegisters; }
bool bit_table(ModbusTable t) { return t == ModbusTable::Coils || t == ModbusTable::DiscreteInputs; }

std::string element_name(const Tag& tag, std::uint32_t e) {
  return tag.name + (tag.length > 1 ? "[" + std::to_string(tag.array_lower + e) + "]" : "");
}

// The points of a tag placed explicitly; empty (with a note) when the place
// does not suit its type or runs past the table's end.
std::vector<ModbusPoint> explicit_points(const Tag& tag, const ModbusPlace& place, std::uint32_t ti,
                                         std::vector<std::string>* notes) {
  if (bit_table(place.table) != (tag.type == IecType::BOOL)) {
    if (notes)
      notes->push_back(tag.name + ": a " + std::string(type_name(tag.type)) + " has no place among the " +
                       std::string(modbus_table_name(place.table)) + "s");
    return {};
  }
  const std::uint32_t width = register_width(tag.type);
  if (place.address + std::uint64_t{tag.length} * width > kTableSize) {
    if (notes) notes->push_back(tag.name + ": its " + std::string(modbus_table_name(place.table)) + "s run past 65535");
    return {};
  }
  const bool writable = table_writable(place.table) && tag.hmi == HmiAccess::ReadWrite;
  std::vector<ModbusPoint> out;
  for (std::uint32_t e = 0; e < tag.length; ++e)
    out.push_back(ModbusPoint{ti, e, place.table, place.address + e * width, width, writable, tag.owner,
                              tag.cell + e, tag.type, ModbusPoint::Status::None, true});
  return out;
}

// The points of a tag by the convention: the elements that fit its range.
std::vector<ModbusPoint> convention_points(const Tag& tag, std::uint32_t ti, std::vector<std::string>* notes) {
  const DirectAddress& a = *tag.address;
  auto r = convention(a);
  if (!r) {
    if (notes) notes->push_back(tag.name + " at " + a.text() + ": no Modbus place by the OpenPLC convention");
    return {};
  }
  const std::uint32_t width = register_width(tag.type);
  const bool writable = table_writable(r->table) && tag.hmi == HmiAccess::ReadWrite;
  std::vector<ModbusPoint> out;
  for (std::uint32_t e = 0; e < tag.length; ++e) {
    std::uint64_t addr;
    if (a.size == AddrSize::Bit) addr = a.first_bit() + e;
    else addr = r->base + (std::uint64_t{a.index} + e) * r->per_index;
    if (addr + width > r->limit) {
      if (notes)
        notes->push_back(element_name(tag, e) + " at " + a.text() + ": beyond the " +
                         std::string(modbus_table_name(r->table)) + " range of the convention");
      break;
    }
    out.push_back(ModbusPoint{ti, e, r->table, static_cast<std::uint32_t>(addr), width, writable, tag.owner,
                              tag.cell + e, tag.type});
  }
  return out;
}

// The places taken so far in one table: first address -> (one past the last, tag, explicit).
struct Taken {
  std::uint64_t end;
  std::uint32_t tag;
  bool explicit_place;
};
using TakenTable = std::map<std::uint32_t, Taken>;

// The place in `taken` that shares an address with [first, end), if any.
const std::pair<const std::uint32_t, Taken>* overlap_in(const TakenTable& taken, std::uint32_t first, std::uint64_t end) {
  auto it = taken.lower_bound(first);
  if (it != taken.begin()) {
    auto before = std::prev(it);
    if (before->second.end > first) return &*before;
  }
  if (it != taken.end() && it->first < end) return &*it;
  return nullptr;
}

}  // namespace

std::string modbus_span_text(const ModbusSpan& s) {
  const std::string name(modbus_table_name(s.table));
  if (s.count <= 1) return name + " " + std::to_string(s.first);
  return name + "s " + std::to_string(s.first) + ".." + std::to_string(std::uint64_t{s.first} + s.count - 1);
}

namespace {

// The status blocks are served only where no tag takes a register of them.
bool status_block_free(const std::vector<ModbusPoint>& v, const Program& p, std::uint32_t base, std::uint32_t end,
                       const char* what, const char* key, std::vector<std::string>* notes) {
  for (const auto& pt : v)
    if (pt.address < end && pt.address + pt.width > base) {
      if (notes)
        notes->push_back(std::string(what) + " not served: input registers " + std::to_string(base) + ".." +
                         std::to_string(end - 1) + " overlap " +
                         (pt.status == ModbusPoint::Status::None ? "tag " + p.tags[pt.tag].name : std::string("the task status block")) +
                         " (move it with modbus: {" + key + ": N})");
      return false;
    }
  return true;
}

}  // namespace

ModbusMap ModbusMap::build(const Program& p, const ModbusSettings& s, std::vector<std::string>* notes,
                           std::vector<ModbusOverlap>* overlaps) {
  ModbusMap m = build(p.tags, s.places, notes, overlaps);
  auto& v = m.tables_[static_cast<int>(ModbusTable::InputRegisters)];
  using S = ModbusPoint::Status;
  auto point = [&v](std::uint32_t address, std::uint32_t width, IecType type, S status, std::uint16_t owner) {
    ModbusPoint pt;
    pt.table = ModbusTable::InputRegisters;
    pt.address = address;
    pt.width = width;
    pt.owner = owner;
    pt.type = type;
    pt.status = status;
    v.push_back(pt);
  };
  if (s.server.task_status && !p.tasks.empty()) {
    const std::uint32_t base = *s.server.task_status;
    const std::uint32_t end = base + kTaskStatusRegisters * static_cast<std::uint32_t>(p.tasks.size());
    if (status_block_free(v, p, base, end, "task status", "task_status", notes))
      for (std::uint16_t t = 0; t < p.tasks.size(); ++t) {
        const std::uint32_t a = base + kTaskStatusRegisters * t;
        point(a + 0, 1, IecType::UINT, S::State, t);
        point(a + 1, 1, IecType::UINT, S::AgeMs, t);
        point(a + 2, 4, IecType::ULINT, S::Scans, t);
        point(a + 6, 2, IecType::UDINT, S::PeriodUs, t);
      }
  }
  if (s.server.store_status) {
    const std::uint32_t a = *s.server.store_status;
    if (status_block_free(v, p, a, a + kStoreStatusRegisters, "store status", "store_status", notes)) {
      point(a + 0, 1, IecType::UINT, S::StoreState, 0);
      point(a + 1, 1, IecType::UINT, S::StoreSinceOk, 0);
      point(a + 2, 2, IecType::UDINT, S::StorePending, 0);
      point(a + 4, 2, IecType::UDINT, S::StoreDropped, 0);
      point(a + 6, 2, IecType::UDINT, S::StoreFailures, 0);
    }
  }
  std::sort(v.begin(), v.end(), [](const ModbusPoint& x, const ModbusPoint& y) { return x.address < y.address; });
  return m;
}

ModbusMap ModbusMap::build(const std::vector<Tag>& tags, const ModbusPlaces& places, std::vector<std::string>* notes,
                           std::vector<ModbusOverlap>* overlaps) {
  ModbusMap m;
  std::array<TakenTable, 4> taken;
  // Explicit places first: a tag placed by hand wins over one that is only
  // there by the convention.
  for (const bool explicit_pass : {true, false}) {
    for (std::uint32_t ti = 0; ti < tags.size(); ++ti) {
      const Tag& tag = tags[ti];
      const ModbusPlace* place = explicit_place(places, ti);
      if (tag.hmi == HmiAccess::None || (place != nullptr) != explicit_pass) continue;
      if (!explicit_pass && !tag.address) continue;
      const auto points = explicit_pass ? explicit_points(tag, *place, ti, notes) : convention_points(tag, ti, notes);
      if (points.empty()) continue;
      const ModbusTable table = points.front().table;
      const std::uint32_t first = points.front().address;
      const std::uint64_t end = std::uint64_t{points.back().address} + points.back().width;
      auto& in_table = taken[static_cast<int>(table)];
      if (const auto* hit = overlap_in(in_table, first, end)) {
        if (overlaps)
          overlaps->push_back(ModbusOverlap{
              ti, hit->second.tag, ModbusSpan{table, first, static_cast<std::uint32_t>(end - first), explicit_pass},
              ModbusSpan{table, hit->first, static_cast<std::uint32_t>(hit->second.end - hit->first), hit->second.explicit_place}});
        continue;
      }
      in_table.emplace(first, Taken{end, ti, explicit_pass});
      auto& out = m.tables_[static_cast<int>(table)];
      out.insert(out.end(), points.begin(), points.end());
    }
  }
  for (auto& t : m.tables_)
    std::sort(t.begin(), t.end(), [](const ModbusPoint& x, const ModbusPoint& y) { return x.address < y.address; });
  return m;
}

const ModbusPoint* ModbusMap::at(ModbusTable t, std::uint32_t address) const {
  const auto& v = tables_[static_cast<int>(t)];
  auto it = std::upper_bound(v.begin(), v.end(), address, [](std::uint32_t a, const ModbusPoint& p) { return a < p.address; });
  if (it == v.begin()) return nullptr;
  --it;
  return address < it->address + it->width ? &*it : nullptr;
}

std::optional<std::vector<const ModbusPoint*>> ModbusMap::range(ModbusTable t, std::uint32_t address,
                                                               std::uint32_t count) const {
  std::vector<const ModbusPoint*> out;
  if (!range(t, address, count, out)) return std::nullopt;
  return out;
}

bool ModbusMap::range(ModbusTable t, std::uint32_t address, std::uint32_t count,
                      std::vector<const ModbusPoint*>& out) const {
  out.clear();
  if (count == 0) return false;
  const std::uint64_t end = std::uint64_t{address} + count;  // no wrap-around
  // One search for the first value; the table is sorted and free of overlaps,
  // so the rest of a mapped range is the points that follow, each starting
  // where the one before ended.
  const auto& v = tables_[static_cast<int>(t)];
  auto it = std::lower_bound(v.begin(), v.end(), address, [](const ModbusPoint& p, std::uint32_t a) { return p.address < a; });
  out.resize(count);  // at most one point per address; shrunk below (no allocation once grown)
  std::size_t n = 0;
  std::uint64_t a = address;
  while (a < end) {
    if (it == v.end() || it->address != a || it->address + it->width > end) {  // unmapped, or a value cut
      out.clear();
      return false;
    }
    out[n++] = &*it;
    a += it->width;
    ++it;
  }
  out.resize(n);
  return true;
}

void print_modbus_map(std::ostream& os, const Program& p, const ModbusMap& m, WordOrder order) {
  os << "Modbus map (OpenPLC convention; 32/64-bit values " << (order == WordOrder::HighFirst ? "high word first" : "low word first")
     << "):\n";
  bool any = false;
  for (int t = 0; t < 4; ++t) {
    const auto& v = m.points(static_cast<ModbusTable>(t));
    for (std::size_t i = 0; i < v.size();) {
      if (v[i].status != ModbusPoint::Status::None) {  // the status blocks: one line a task, one for the store
        if (v[i].status == ModbusPoint::Status::State)
          os << "  input registers " << v[i].address << ".." << v[i].address + kTaskStatusRegisters - 1 << "  status of task "
             << p.tasks[v[i].owner]->config().name << " (state, age ms, scans, period us)  read only\n";
        if (v[i].status == ModbusPoint::Status::StoreState)
          os << "  input registers " << v[i].address << ".." << v[i].address + kStoreStatusRegisters - 1
             << "  status of the store (state, s since commit, pending, lost, failures)  read only\n";
        ++i;
        continue;
      }
      // One line per tag: its elements are consecutive.
      std::size_t j = i;
      while (j + 1 < v.size() && v[j + 1].tag == v[i].tag && v[j + 1].status == ModbusPoint::Status::None) ++j;
      const Tag& tag = p.tags[v[i].tag];
      const std::uint32_t last = v[j].address + v[j].width - 1;
      os << "  " << modbus_table_name(v[i].table) << (v[i].address == last ? " " : "s ") << v[i].address
         << (v[i].address == last ? "" : ".." + std::to_string(last)) << "  " << tag.name << " "
         << type_name(tag.type) << (tag.length > 1 ? "[" + std::to_string(tag.length) + "]" : "")
         << (v[i].explicit_place ? " (explicit)" : " at " + tag.address->text()) << (v[i].writable ? "  read/write" : "  read only")
         << "\n";
      any = true;
      i = j + 1;
    }
  }
  if (!any) os << "  (no tag with HMI access and a direct address or a modbus: place)\n";
}

}  // namespace syncplc
