// Building the Program from checked declarations: blocks created by their
// factories, each task's image laid out (owned tags, copies of other tasks'
// tags, pins), connections as copies, snapshot channels, drivers bound.
#include <algorithm>
#include <map>
#include <stdexcept>

#include "runtime/project/read_st.hpp"
#include "runtime/project/stages.hpp"

namespace syncplc {
namespace {

class LoaderBlockSetup final : public BlockSetup {
 public:
  LoaderBlockSetup(const InstanceDecl& in, std::vector<Cell> params, std::vector<bool> connected, std::int64_t period,
                   std::uint64_t seed, Diagnostics& d)
      : in_(in), params_(std::move(params)), connected_(std::move(connected)), period_(period), seed_(seed), d_(d) {}
  const std::string& instance_name() const override { return in_.name; }
  const BlockTypeInfo& type() const override { return *in_.type; }
  IecType datatype() const override { return in_.datatype.value_or(IecType::LREAL); }
  Cell param_cell(int index) const override {
    if (index < 0 || static_cast<std::size_t>(index) >= params_.size())
      throw std::out_of_range(in_.type->name + ": no such parameter");
    return params_[static_cast<std::size_t>(index)];
  }
  // What the factory reads of the wiring becomes part of the instance's
  // signature (instance_signature.hpp): an online change that changes it
  // must not keep the instance as it is.
  bool connected(int pin) const override {
    const bool c = connected_.at(static_cast<std::size_t>(pin));
    seen_[static_cast<std::size_t>(pin)] = c ? WiringSeen::Wired : WiringSeen::Unwired;
    return c;
  }
  std::vector<WiringSeen> take_seen() { return std::move(seen_); }
  std::uint32_t pin_length(int pin) const override { return in_.pin_length.at(static_cast<std::size_t>(pin)); }
  std::int64_t task_period_ns() const override {
    period_read_ = true;  // a sampling time fixed at creation: part of the signature
    return period_;
  }
  bool period_read() const { return period_read_; }
  std::int64_t task_watchdog_ns() const override { return watchdog_; }
  void set_watchdog(std::int64_t ns) { watchdog_ = ns; }
  std::uint64_t seed() const override { return seed_; }
  void error(const std::string& message) override { d_.error(in_.loc, in_.name + " (" + in_.type->name + "): " + message); }
  void unknown_param(std::string_view name) const override {
    std::string names;
    for (const auto& p : in_.type->params) names += (names.empty() ? "" : ", ") + p.name;
    d_.error(in_.loc, in_.name + " (" + in_.type->name + "): its factory reads parameter '" + std::string(name) + "', which " +
                          in_.type->name + " does not declare (" + (names.empty() ? "it has none" : names) + ")");
  }

 private:
  const InstanceDecl& in_;
  std::vector<Cell> params_;
  std::vector<bool> connected_;
  mutable std::vector<WiringSeen> seen_ = std::vector<WiringSeen>(connected_.size(), WiringSeen::NotAsked);
  mutable bool period_read_ = false;
  std::int64_t watchdog_ = 0;
  std::int64_t period_;
  std::uint64_t seed_;
  Diagnostics& d_;
};

bool pin_connected(const InstanceDecl& in, std::size_t p) {
  const auto& es = in.element_source[p];
  return in.source[p] >= 0 || in.source[p] == kBrokenSource || in.input(p) ||
         std::any_of(es.begin(), es.end(), [](int c) { return c >= 0; });
}

// How each pin of `in` is fed (the signature's wiring part).
std::vector<PinFeed> pin_feeds(const InstanceDecl& in, const Wiring& w) {
  std::vector<PinFeed> feeds(in.type->pins.size());
  auto source_text = [&](int c) -> std::string {
    return c >= 0 && static_cast<std::size_t>(c) < w.connections.size() ? w.connections[static_cast<std::size_t>(c)].src.text
                                                                        : std::string("?");
  };
  for (std::size_t q = 0; q < feeds.size(); ++q) {
    if (in.type->pins[q].dir != PinDir::In) continue;
    PinFeed& f = feeds[q];
    if (in.source[q] >= 0 || in.source[q] == kBrokenSource) {
      f.kind = PinFeed::Kind::Wired;
      f.from = source_text(in.source[q]);
    } else if (in.input(q)) {
      f.kind = PinFeed::Kind::Constant;
    }
    const auto& es = in.element_source[q];
    if (std::any_of(es.begin(), es.end(), [](int c) { return c >= 0; })) {
      f.kind = PinFeed::Kind::Wired;
      f.from.clear();
      for (std::size_t k = 0; k < es.size(); ++k) f.from += (k ? "," : "") + (es[k] >= 0 ? source_text(es[k]) : "-");
    }
  }
  return feeds;
}

struct Created {
  std::unique_ptr<Block> block;
  std::vector<WiringSeen> seen;
  std::int64_t period_ns = 0;  // the task period, when the factory read it
};

std::vector<Created> create_blocks(const Declarations& p, Diagnostics& diags) {
  std::vector<Created> blocks(p.instances.size());
  std::size_t i = 0;
  for (const auto& in : p.instances) {
    Created& made = blocks[i++];
    auto& block = made.block;
    if (!in.values_ok || (in.type->is_generic() && !in.datatype)) continue;  // already reported
    std::vector<bool> connected;
    for (std::size_t q = 0; q < in.type->pins.size(); ++q) connected.push_back(pin_connected(in, q));
    LoaderBlockSetup setup(in, in.param_cells, connected, p.tasks[static_cast<std::size_t>(in.task)].cfg.period_ns,
                           mix_seed(p.seed, in.name), diags);
    if (const TaskConfig& tc = p.tasks[static_cast<std::size_t>(in.task)].cfg; tc.watchdog) setup.set_watchdog(tc.watchdog_ns);
    std::size_t before = diags.size();
    try {
      block = in.type->create(setup);
    } catch (const std::exception& e) {
      diags.error(in.loc, in.name + " (" + in.type->name + "): " + e.what());
    }
    made.seen = setup.take_seen();
    if (setup.period_read()) made.period_ns = p.tasks[static_cast<std::size_t>(in.task)].cfg.period_ns;
    if (!block && diags.size() == before) diags.error(in.loc, in.name + " (" + in.type->name + ") could not be created");
    if (block && in.retain && block->retain_cells() == 0)
      diags.error(in.retain_loc, in.name + " (" + in.type->name + ") has no state to retain (retain: and persistent: "
                  "are for blocks with state, e.g. counters and UNIT_DELAY; docs/store.md)");
  }
  return blocks;
}

}  // namespace

// The build's access to the images it lays out (image_access.hpp): no thread
// runs the program yet. Only build_program may take it.
class ProgramBuilder {
  static ImageAccess access() { return ImageAccess{}; }
  friend std::unique_ptr<Program> build_program(Declarations& p, const Wiring& w, const BlockOrder& o, Diagnostics& diags);
};

std::unique_ptr<Program> build_program(Declarations& p, const Wiring& w, const BlockOrder& o, Diagnostics& diags) {
  const ImageAccess access = ProgramBuilder::access();
  // Blocks are created whatever failed before, so that their factories' errors are reported too.
  std::vector<Created> created = create_blocks(p, diags);
  if (!diags.empty()) return nullptr;
  auto prog = std::make_unique<Program>();
  prog->code = p.st;
  prog->name = p.name;
  prog->version = p.version;
  prog->file = p.file;
  prog->seed = p.seed;
  const std::size_t nt = p.tasks.size();
  for (std::size_t i = 0; i < nt; ++i) prog->tasks.push_back(std::make_unique<Task>(static_cast<std::uint16_t>(i), p.tasks[i].cfg));

  // --- image layout: owned tags, foreign copies, pins -------------------------
  std::vector<std::uint32_t> next(nt, 0);
  // Cells are numbered in 32 bits: a task's image may not outgrow them.
  bool too_large = false;
  auto grow = [&](std::size_t task, std::uint32_t cells) {
    if (!__builtin_add_overflow(next[task], cells, &next[task])) return;
    if (!too_large)
      diags.error(p.tasks[task].loc, "task " + p.tasks[task].cfg.name + " has more than 2^32 cells of tags and pins");
    too_large = true;
    next[task] = 0;
  };
  for (auto& td : p.tags) {
    td.tag.cell = next[td.tag.owner];
    grow(td.tag.owner, td.tag.length);
  }
  // Retained block state sits after the tags, inside the published range.
  std::vector<std::uint32_t> retain_cell(p.instances.size(), 0);
  for (std::size_t i = 0; i < p.instances.size(); ++i)
    if (p.instances[i].retain) {
      auto t = static_cast<std::size_t>(p.instances[i].task);
      retain_cell[i] = next[t];
      grow(t, created[i].block->retain_cells());
    }
  for (std::size_t t = 0; t < nt; ++t) prog->tasks[t]->owned_cells = next[t];
  std::vector<std::map<int, std::uint32_t>> foreign(nt);  // task -> tag -> local cell
  auto local_cell = [&](int tag, std::size_t task) -> std::uint32_t {
    const auto& tg = p.tags[static_cast<std::size_t>(tag)].tag;
    if (tg.owner == task) return tg.cell;
    auto& f = foreign[task];
    auto it = f.find(tag);
    if (it != f.end()) return it->second;
    std::uint32_t c = next[task];
    grow(task, tg.length);
    f[tag] = c;
    return c;
  };
  // Foreign copies are assigned in a fixed order: connections, then drivers.
  for (const auto& c : w.connections)
    if (!c.src.is_pin) local_cell(c.src.tag, static_cast<std::size_t>(p.instances[static_cast<std::size_t>(c.dst.instance)].task));
  for (const auto& dd : p.drivers)
    for (std::size_t i = 0; i < dd.channel_tag.size(); ++i)
      if (dd.channel_tag[i] >= 0) local_cell(dd.channel_tag[i], static_cast<std::size_t>(dd.task));
  std::vector<std::vector<std::uint32_t>> pin_cells(p.instances.size());
  for (std::size_t i = 0; i < p.instances.size(); ++i) {
    auto t = static_cast<std::size_t>(p.instances[i].task);
    pin_cells[i].reserve(p.instances[i].type->pins.size());
    for (std::size_t q = 0; q < p.instances[i].type->pins.size(); ++q) {
      pin_cells[i].push_back(next[t]);
      grow(t, p.instances[i].pin_length[q]);
    }
  }
  if (too_large) return nullptr;
  for (std::size_t t = 0; t < nt; ++t) prog->tasks[t]->image(access).assign(next[t], Cell{});

  // --- initial values ----------------------------------------------------------
  for (const auto& td : p.tags) {
    auto& img = prog->tasks[td.tag.owner]->image(access);
    std::copy(td.tag.init.begin(), td.tag.init.end(), img.begin() + td.tag.cell);
  }
  for (std::size_t t = 0; t < nt; ++t)
    for (const auto& [tag, cell] : foreign[t]) {
      const auto& init = p.tags[static_cast<std::size_t>(tag)].tag.init;
      std::copy(init.begin(), init.end(), prog->tasks[t]->image(access).begin() + cell);
    }
  for (std::size_t i = 0; i < p.instances.size(); ++i) {
    auto& img = prog->tasks[static_cast<std::size_t>(p.instances[i].task)]->image(access);
    for (const auto& [q, v] : p.instances[i].pin_values.lists())
      for (std::uint32_t k = 0; !v.empty() && k < p.instances[i].pin_length[q]; ++k)
        img[pin_cells[i][q] + k] = v.size() == 1 ? v[0] : v[k];
  }

  for (std::size_t t = 0; t < nt; ++t) prog->tasks[t]->unit_delays = o.delays[t];
  const auto& order = o.order;

  // --- blocks, in execution order -------------------------------------------------
  std::vector<std::uint32_t> position(p.instances.size(), 0);
  for (std::size_t t = 0; t < nt; ++t) {
    auto& task = *prog->tasks[t];
    task.blocks.reserve(order[t].size());
    for (std::size_t k = 0; k < order[t].size(); ++k) {
      auto i = static_cast<std::size_t>(order[t][k]);
      auto& in = p.instances[i];
      position[i] = static_cast<std::uint32_t>(k);
      BlockInstance bi;
      bi.name = in.name;
      bi.type = in.type;
      bi.datatype = in.datatype.value_or(IecType::LREAL);
      bi.pin_cell = pin_cells[i];
      bi.pin_length = in.pin_length;
      bi.block = std::move(created[i].block);
      InstanceSignature& sig = bi.signature;
      sig.type = in.type;
      // The state's identity: a CTU<INT>'s count is no CTU<DINT>'s.
      sig.type_name = in.type->is_generic() ? in.type->name + "<" + std::string(type_name(bi.datatype)) + ">" : in.type->name;
      sig.pin_length = in.pin_length;
      sig.params = in.param_cells;
      sig.feeds = pin_feeds(in, w);
      sig.seen = std::move(created[i].seen);
      sig.period_ns = created[i].period_ns;
      sig.state = {bi.block->retain_cells(), bi.block->retain_layout()};
      if (in.retain) {
        bi.retain_cell = retain_cell[i];
        bi.retain_length = bi.block->retain_cells();
        bi.block->save_retain(&task.image(access)[bi.retain_cell]);
        task.retained_blocks.push_back(static_cast<std::uint32_t>(k));
        prog->retained.push_back({in.name, sig.state_identity(), static_cast<std::uint16_t>(t),
                                  static_cast<std::uint32_t>(k), bi.retain_cell, bi.retain_length, in.persistent});
      }
      task.blocks.push_back(std::move(bi));
      prog->instances[in.name] = {static_cast<std::uint16_t>(t), static_cast<std::uint32_t>(k)};
    }
  }

  // --- links: each target's position, and the first Block::link -----------------
  for (std::size_t i = 0; i < p.instances.size(); ++i) {
    const auto& in = p.instances[i];
    if (in.links.empty()) continue;
    auto& task = *prog->tasks[static_cast<std::size_t>(in.task)];
    auto& bi = task.blocks[position[i]];
    bi.signature.links.assign(in.type->links.size(), std::string{});
    for (const auto& l : in.links) {
      if (l.instance < 0) continue;  // reported by check_links; the program is not kept
      bi.links.push_back({l.link, l.element, position[static_cast<std::size_t>(l.instance)]});
      std::string& names = bi.signature.links[static_cast<std::size_t>(l.link)];
      names += (l.element == 0 ? "" : ",") + l.target;
    }
  }
  for (auto& task : prog->tasks) task->relink();

  // --- connections as copies -----------------------------------------------------
  // A connection copies its length: 1 for scalars and elements, n for whole arrays.
  auto pin_at = [&](const Endpoint& e) {
    return pin_cells[static_cast<std::size_t>(e.instance)][static_cast<std::size_t>(e.pin)] + e.element.value_or(0);
  };
  for (const auto& c : w.connections) {
    std::uint32_t n = 1;
    endpoint_type(p, c.dst, &n);
    if (c.dst.is_pin) {
      const auto& di = p.instances[static_cast<std::size_t>(c.dst.instance)];
      auto t = static_cast<std::size_t>(di.task);
      std::uint32_t src = c.src.is_pin ? pin_at(c.src) : local_cell(c.src.tag, t) + c.src.element.value_or(0);
      auto& bi = prog->tasks[t]->blocks[position[static_cast<std::size_t>(c.dst.instance)]];
      bi.copy_in.push_back({src, pin_at(c.dst), n});
    } else {
      const auto& si = p.instances[static_cast<std::size_t>(c.src.instance)];
      auto t = static_cast<std::size_t>(si.task);
      const auto& tg = p.tags[static_cast<std::size_t>(c.dst.tag)].tag;
      auto& bi = prog->tasks[t]->blocks[position[static_cast<std::size_t>(c.src.instance)]];
      bi.copy_out.push_back({pin_at(c.src), tg.cell + c.dst.element.value_or(0), n});
    }
  }

  // --- snapshot channels: [0] external, then one per consuming task -------------
  for (std::size_t t = 0; t < nt; ++t) prog->tasks[t]->channels.push_back(std::make_unique<SnapshotChannel>(false));
  for (std::size_t t = 0; t < nt; ++t) {
    std::map<std::uint16_t, Inbound> by_producer;
    for (const auto& [tag, cell] : foreign[t]) {
      const auto& tg = p.tags[static_cast<std::size_t>(tag)].tag;
      auto& ib = by_producer[tg.owner];
      ib.producer = tg.owner;
      ib.copies.push_back({tg.cell, cell, tg.length});
    }
    for (auto& [producer, ib] : by_producer) {
      auto& ptask = *prog->tasks[producer];
      ptask.channels.push_back(std::make_unique<SnapshotChannel>());
      ib.channel = ptask.channels.back().get();
      prog->tasks[t]->inbound.push_back(std::move(ib));
    }
  }

  // --- drivers and safe values -----------------------------------------------------
  for (auto& dd : p.drivers) {
    auto t = static_cast<std::size_t>(dd.task);
    auto& task = *prog->tasks[t];
    std::vector<Cell*> cells(dd.channel_tag.size(), nullptr);
    DriverBinding b;
    b.type = dd.type;
    b.task = static_cast<std::uint16_t>(t);
    for (std::size_t i = 0; i < dd.channel_tag.size(); ++i) {
      int ti = dd.channel_tag[i];
      b.bound_tags.push_back(ti < 0 ? "" : p.tags[static_cast<std::size_t>(ti)].tag.name);
      if (ti < 0) continue;
      std::uint32_t c = local_cell(ti, t);
      cells[i] = &task.image(access)[c];
      const auto& tg = p.tags[static_cast<std::size_t>(ti)].tag;
      if (dd.driver->channels()[i].dir == PinDir::Out && tg.owner != t && !tg.safe.empty())
        for (std::uint32_t k = 0; k < tg.length; ++k) task.safe_values.emplace_back(c + k, tg.safe[k]);
    }
    dd.driver->bind(cells);
    b.cells = cells;
    b.settings = dd.settings;
    task.drivers.push_back(dd.driver.get());
    b.driver = std::move(dd.driver);
    prog->drivers.push_back(std::move(b));
  }
  for (const auto& td : p.tags)
    if (!td.tag.safe.empty())
      for (std::uint32_t k = 0; k < td.tag.length; ++k)
        prog->tasks[td.tag.owner]->safe_values.emplace_back(td.tag.cell + k, td.tag.safe[k]);

  for (auto& td : p.tags) prog->tags.push_back(td.tag);
  prog->max_forces = p.max_forces;
  for (auto& t : prog->tasks) {
    t->force_capacity = p.max_forces;  // every force may be in one task
    t->finalize();
  }

  for (const auto& [ref, loc] : p.traces) {
    std::string err;
    auto r = prog->resolve(ref, &err);
    if (!r) diags.error(loc, "trace: " + err);
    else if (r->length != 1) diags.error(loc, "trace: " + ref + " is an array; trace its elements (" + ref + "[i])");
    else prog->traces.push_back({ref, *r});
  }
  for (const auto& [ref, loc] : p.watch) {
    if (!prog->find_tag(ref)) diags.error(loc, "watch: unknown tag '" + ref + "'");
    else prog->watch.push_back(ref);
  }
  return prog;  // built, though it may have errors (the loader discards it then, after build_metrics reported its own)
}

// metrics: {axis_errors} in axis order; an array tag gives one axis an element.
MetricsSettings build_metrics(const Declarations& p, const Program& prog, Diagnostics& diags) {
  MetricsSettings m;
  m.from_ns = p.metrics_from_ns;
  for (const auto& [ref, loc] : p.axis_errors) {
    std::string err;
    auto r = prog.resolve(ref, &err);
    if (!r) continue;  // reported by check_refs
    if (r->type != IecType::LREAL && r->type != IecType::REAL) {
      diags.error(loc, "metrics: " + ref + " is " + std::string(type_name(r->type)) + "; axis errors are REAL or LREAL");
      continue;
    }
    const Tag* t = prog.find_tag(ref);
    for (std::uint32_t k = 0; k < r->length; ++k) {
      CellRef one = *r;
      one.cell += k;
      one.length = 1;
      std::string label = r->length == 1 ? ref : ref + "[" + std::to_string((t ? t->array_lower : 1) + k) + "]";
      m.axis_errors.push_back({label, one});
    }
  }
  if (!m.axis_errors.empty()) m.contour = resolve_contour_metric(p.metrics_contour, prog, m.axis_errors.front().ref.task, diags);
  return m;
}

store::StoreSettings build_store(const Declarations& p) {
  store::StoreSettings s = p.store;
  for (std::uint32_t i = 0; i < p.tags.size(); ++i)
    if (p.tags[i].trend) {
      s.trends.push_back(*p.tags[i].trend);
      s.trends.back().tag = i;  // Program::tags keeps the declarations' order
    }
  return s;
}

ModbusSettings build_modbus(const Declarations& p) {
  ModbusSettings s;
  s.server = p.modbus;
  for (const auto& td : p.tags) s.places.push_back(td.modbus);  // Program::tags keeps the declarations' order
  return s;
}

}  // namespace syncplc
