// Who writes each tag (one block output, one driver input, or nobody: then
// the HMI and tests), which task owns it, and the checks on what may be
// written from outside: overlapping addresses and Modbus places, queues
// large enough for one Modbus write.
#include <algorithm>
#include <map>
#include <tuple>

#include "runtime/project/modbus_settings.hpp"
#include "runtime/project/stages.hpp"

namespace syncplc {
namespace {

// Two tags may not share a coil or register. Checked with the map the server
// will build; a tag whose modbus: key was wrong is left out so that it
// causes no second error.
std::vector<Tag> modbus_tags(const Declarations& p) {
  std::vector<Tag> tags;
  for (const auto& td : p.tags) {
    tags.push_back(td.tag);
    if (td.modbus_failed) tags.back().hmi = HmiAccess::None;
  }
  return tags;
}

ModbusPlaces modbus_places(const Declarations& p) {
  ModbusPlaces places;
  for (const auto& td : p.tags) places.push_back(td.modbus);
  return places;
}

}  // namespace

// Two tags may not share a bit of the I, Q or M area. Sorted by first bit and
// swept, so that a project of many addressed tags is checked in n log n;
// each overlap is reported at the later-declared tag's address.
void check_addresses(const Declarations& p, Diagnostics& diags) {
  struct Span {
    char area;
    std::uint64_t first, end;
    std::size_t tag;
  };
  std::vector<Span> spans;
  for (std::size_t i = 0; i < p.tags.size(); ++i) {
    const Tag& t = p.tags[i].tag;
    if (t.address) spans.push_back({static_cast<char>(t.address->area), t.address->first_bit(), t.address->end_bit(t.length), i});
  }
  std::sort(spans.begin(), spans.end(), [](const Span& a, const Span& b) {
    return std::tie(a.area, a.first, a.tag) < std::tie(b.area, b.first, b.tag);
  });
  std::vector<std::pair<std::size_t, std::size_t>> pairs;  // (later, earlier) declared
  std::vector<const Span*> open;  // spans of this area that reach past the current first bit
  for (std::size_t k = 0; k < spans.size(); ++k) {
    const Span& s = spans[k];
    std::erase_if(open, [&](const Span* o) { return o->area != s.area || o->end <= s.first; });
    for (const Span* o : open) pairs.emplace_back(std::max(s.tag, o->tag), std::min(s.tag, o->tag));
    open.push_back(&s);
  }
  std::sort(pairs.begin(), pairs.end());
  for (const auto& [later, earlier] : pairs) {
    const TagDecl& a = p.tags[later];
    const TagDecl& o = p.tags[earlier];
    diags.error(a.address_loc, "address " + a.tag.address->text() + " of " + a.tag.name + " overlaps " +
                                   o.tag.address->text() + " of " + o.tag.name + " (defined at " + o.tag.loc.text() + ")");
  }
}

void check_modbus_places(const Declarations& p, Diagnostics& diags) {
  std::vector<SourceLoc> place_loc;
  for (const auto& td : p.tags) place_loc.push_back(td.modbus_loc);
  check_modbus_overlaps(modbus_tags(p), modbus_places(p), place_loc, diags);
}

void find_owners(Declarations& p, const Wiring& w, Diagnostics& diags) {
  auto note_writer = [&](int ti, int task, const std::string& who, const SourceLoc& loc) {
    auto& td = p.tags[static_cast<std::size_t>(ti)];
    if (td.writer_task >= 0) {
      diags.error(loc, "tag " + td.tag.name + " has two writers: " + td.writer + " and " + who);
      return;
    }
    td.writer_task = task;
    td.writer = who;
    td.writer_loc = loc;
    td.tag.written_every_scan = true;
  };
  std::map<std::pair<int, std::uint32_t>, bool> seen_element;
  std::vector<std::uint32_t> elements_written(p.tags.size(), 0);
  for (const auto& c : w.connections) {
    if (!c.dst.is_pin) {
      auto& td = p.tags[static_cast<std::size_t>(c.dst.tag)];
      // Different elements of one array tag may come from different blocks of one task.
      if (c.dst.element) {
        auto key = std::make_pair(c.dst.tag, *c.dst.element);
        if (seen_element[key]) { diags.error(c.loc, "tag element " + c.dst.text + " has two writers"); continue; }
        seen_element[key] = true;
        ++elements_written[static_cast<std::size_t>(c.dst.tag)];
        int task = p.instances[static_cast<std::size_t>(c.src.instance)].task;
        if (td.writer_task >= 0 && td.writer_task != task)
          diags.error(c.loc, "tag " + td.tag.name + " is written from two tasks (" + td.writer + " and block " + c.src.text + ")");
        else if (td.writer_task < 0) { td.writer_task = task; td.writer = "block " + c.src.text; td.writer_loc = c.loc; }
        continue;
      }
      note_writer(c.dst.tag, p.instances[static_cast<std::size_t>(c.src.instance)].task, "block " + c.src.text, c.loc);
    } else if (!c.src.is_pin) {
      p.tags[static_cast<std::size_t>(c.src.tag)].reader_tasks.push_back(p.instances[static_cast<std::size_t>(c.dst.instance)].task);
    }
  }
  for (const auto& dd : p.drivers) {
    const auto& chans = dd.driver->channels();
    for (std::size_t i = 0; i < chans.size(); ++i) {
      int ti = dd.channel_tag[i];
      if (ti < 0) continue;
      if (chans[i].dir == PinDir::In) note_writer(ti, dd.task, "driver " + dd.name + "." + chans[i].name, dd.channel_loc[i]);
      else p.tags[static_cast<std::size_t>(ti)].reader_tasks.push_back(dd.task);
    }
  }
  for (std::size_t i = 0; i < p.tags.size(); ++i)
    if (elements_written[i] == p.tags[i].tag.length) p.tags[i].tag.written_every_scan = true;
  for (auto& td : p.tags) {
    int explicit_task = td.task.empty() ? -1 : p.task_index(td.task);
    if (td.writer_task >= 0) {
      if (explicit_task >= 0 && explicit_task != td.writer_task)
        diags.error(td.task_loc, "tag " + td.tag.name + " is written by " + td.writer + " in task " +
                                  p.tasks[static_cast<std::size_t>(td.writer_task)].cfg.name + ", not in task " + td.task);
      td.tag.owner = static_cast<std::uint16_t>(td.writer_task);
    } else if (explicit_task >= 0) {
      td.tag.owner = static_cast<std::uint16_t>(explicit_task);
    } else if (!td.reader_tasks.empty()) {
      td.tag.owner = static_cast<std::uint16_t>(td.reader_tasks.front());
    } else {
      td.tag.owner = 0;
    }
    td.tag.writer = td.writer;
  }
}

void size_write_queues(Declarations& p, Diagnostics& diags) {
  if (p.modbus.read_only) return;
  const auto most = largest_modbus_writes(modbus_tags(p), modbus_places(p), p.tasks.size());
  for (std::size_t i = 0; i < p.tasks.size(); ++i) {
    TaskDecl& td = p.tasks[i];
    if (most[i] <= td.cfg.write_queue) continue;
    if (td.write_queue_loc)
      diags.error(*td.write_queue_loc, "write_queue " + std::to_string(td.cfg.write_queue) + " of task " + td.cfg.name +
                                        " cannot hold one Modbus write to its tags: a request can queue " +
                                        std::to_string(most[i]) + " values to it at once");
    else
      td.cfg.write_queue = most[i];
  }
}

namespace {

// What to write instead of a tag that a block or a driver overwrites every
// scan: for the HMI, a tag of its own; for --set, what the writer reads.
std::string hmi_instead(const TagDecl& td) {
  return "make it hmi: read, or give the HMI a tag of its own (hmi: readwrite, written by nobody) and combine the two in "
         "the program, e.g. " + td.tag.name + " OR an HMI button into an OR block";
}
std::string set_instead(const TagDecl& td) {
  if (td.writer.rfind("driver ", 0) == 0) {
    const std::string channel = td.writer.substr(7), driver = channel.substr(0, channel.find('.'));
    return "set the driver's settings (--set " + driver + ".key=value), or in a scan-cycle test its channel " + channel;
  }
  const std::string block = td.writer.substr(6, td.writer.find('.') - 6);  // "block n.OUT"
  return "set what block " + block + " reads: its parameters (--set " + block + ".param=value) or the tags wired to its inputs";
}

}  // namespace

// A value written from outside into a tag that a block or a driver writes
// every scan is overwritten before anything reads it: an HMI write (hmi:
// readwrite) and --set tag=value would silently do nothing.
void check_writes(const Declarations& p, Diagnostics& diags) {
  for (const auto& td : p.tags) {
    if (td.writer.empty()) continue;  // nobody writes it: the HMI and --set may
    // An array some of whose elements a block writes loses those elements of the write.
    const std::string what = td.tag.written_every_scan ? "it" : "elements of it";
    const std::string who = td.writer + " (" + td.writer_loc.text() + ")";
    if (td.tag.hmi == HmiAccess::ReadWrite)
      diags.error(td.hmi_loc, "tag " + td.tag.name + " is hmi: readwrite, but " + who + " writes " + what +
                                  " every scan and wins: an HMI write would be overwritten in the same scan; " +
                                  hmi_instead(td));
    if (td.init_from_cli)
      diags.error(SourceLoc{"command line", 0, 0}, "--set " + td.tag.name + ": " + who + " writes " +
                                                       (td.tag.written_every_scan ? "the tag" : "elements of the tag") +
                                                       " every scan and wins: the value would be overwritten on the first "
                                                       "scan; " + set_instead(td));
  }
}

}  // namespace syncplc
