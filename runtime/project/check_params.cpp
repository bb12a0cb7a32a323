// Parameters and constant inputs: --set overrides applied, every value
// parsed in its declared type and unit, ranges checked, array pins sized.
#include "runtime/core/param_range.hpp"
#include "runtime/project/stages.hpp"

namespace syncplc {

void apply_overrides(const LoadOptions& opts, const std::set<std::string>& driver_overrides, Declarations& p,
                     Diagnostics& diags) {
  SourceLoc cli{"command line", 0, 0};
  for (const auto& o : opts.overrides) {
    if (driver_overrides.count(o.instance)) continue;  // applied to the driver's settings
    int ii = p.instance_index(o.instance);
    if (ii < 0) {
      int ti = p.tag_index(o.instance);
      if (ti >= 0 && o.param.empty()) { p.cli_tag_values.emplace_back(ti, o.value); continue; }
      diags.error(cli, "--set " + o.instance + "." + o.param + ": no block instance '" + o.instance + "'");
      continue;
    }
    auto& in = p.instances[static_cast<std::size_t>(ii)];
    int pi = in.type->param_index(o.param);
    if (pi >= 0) { in.param_override.emplace_back(pi, o.value); continue; }
    int pin = in.type->pin_index(o.param);
    if (pin >= 0 && in.type->pins[static_cast<std::size_t>(pin)].dir == PinDir::In) {
      diags.error(cli, "--set " + o.instance + "." + o.param + ": that is a pin; --set takes parameters");
      continue;
    }
    diags.error(cli, "--set " + o.instance + "." + o.param + ": " + in.type->name + " has no parameter '" + o.param + "'");
  }
  for (const auto& [ti, value] : p.cli_tag_values) {
    auto& td = p.tags[static_cast<std::size_t>(ti)];
    ConfigNode n;
    n.kind = ConfigNode::Kind::Scalar;
    n.scalar = value;
    n.loc = cli;
    auto v = parse_tag_values(td.tag, n, "--set init", diags);
    if (!v.empty()) td.tag.init = v;
    td.init_from_cli = true;
  }
}

void check_params(Declarations& p, Diagnostics& diags) {
  for (auto& in : p.instances) {
    for (std::size_t q = 0; q < in.type->params.size(); ++q) {
      const auto& decl = in.type->params[q];
      std::string text = decl.default_value;
      SourceLoc loc = in.loc;
      if (const ConfigNode* v = in.param(q)) { text = v->scalar; loc = v->loc; }
      if (const std::string* o = in.override_of(q)) { text = *o; loc = SourceLoc{"command line", 0, 0}; }
      if (text.empty()) {  // a mandatory parameter left out: reported by read_blocks
        in.values_ok = in.params_ok = false;
        in.param_cells.emplace_back();
        continue;
      }
      auto v = parse_literal(decl.type, decl.unit, text, loc, in.name + "." + decl.name, diags);
      if (v) {
        const std::string why = param_range_error(in.name + "." + decl.name, text, cell_as_double(decl.type, *v),
                                                  decl.min, decl.max, decl.unit);
        if (!why.empty()) {
          diags.error(loc, why);
          v.reset();
        }
      }
      if (!v) { in.values_ok = false; in.params_ok = false; }
      in.param_cells.push_back(v.value_or(Cell{}));
    }
    if (!in.params_ok) continue;
    for (std::size_t q = 0; q < in.type->pins.size(); ++q) {
      const auto& decl = in.type->pins[q];
      if (!decl.is_array()) continue;
      auto k = static_cast<std::size_t>(in.type->param_index(decl.length_param));
      double len = cell_as_double(in.type->params[k].type, in.param_cells[k]);
      const std::string why = pin_length_error(in.name + "." + decl.length_param,
                                               format_value(in.type->params[k].type, in.param_cells[k]), len, decl.name,
                                               decl.max_length);
      if (!why.empty()) {
        SourceLoc loc = in.param(k) ? in.param(k)->loc : in.loc;
        if (in.override_of(k)) loc = SourceLoc{"command line", 0, 0};
        diags.error(loc, why);
        in.params_ok = in.values_ok = false;
        break;
      }
      in.pin_length[q] = static_cast<std::uint32_t>(len);
    }
  }
}

void check_values(Declarations& p, Diagnostics& diags) {
  for (auto& in : p.instances) {
    in.pin_values.clear();
    for (std::size_t q = 0; q < in.type->pins.size(); ++q) {
      const auto& decl = in.type->pins[q];
      IecType pt = decl.cls == TypeClass::Exact ? decl.type : in.datatype.value_or(IecType::LREAL);
      const std::string what = in.name + "." + decl.name;
      if (const ConfigNode* v = in.input(q)) {
        if (v->is_scalar()) {
          // One value: the scalar pin's value, or every element of an array pin.
          if (auto c = parse_literal(pt, decl.unit, v->scalar, v->loc, what, diags)) in.pin_values.of(q).push_back(*c);
          else in.values_ok = false;
        } else if (v->is_list() && decl.is_array()) {
          if (!in.params_ok) continue;  // its length is unknown
          const std::uint32_t len = in.pin_length[q];
          if (v->items.size() != len) {
            diags.error(v->loc, what + ": " + std::to_string(v->items.size()) + " values for ARRAY[1.." + std::to_string(len) +
                                 "] (give one value for every element, or a single value for all)");
            in.values_ok = false;
            continue;
          }
          std::vector<Cell> cells;
          cells.reserve(len);
          for (std::size_t k = 0; k < v->items.size(); ++k) {
            const auto& item = v->items[k];
            std::optional<Cell> c;
            if (!item.is_scalar()) diags.error(item.loc, what + "[" + std::to_string(k + 1) + "]: expected a value");
            else c = parse_literal(pt, decl.unit, item.scalar, item.loc, what + "[" + std::to_string(k + 1) + "]", diags);
            if (c) cells.push_back(*c);
            else in.values_ok = false;
          }
          if (!cells.empty()) in.pin_values.of(q) = std::move(cells);
        } else {
          diags.error(v->loc, what + (decl.is_array() ? ": expected a value or a list of values" : ": expected a value"));
          in.values_ok = false;
        }
      } else if (!decl.init.empty()) {
        std::string err;
        if (auto c = parse_value(pt, decl.init, &err)) in.pin_values.of(q).push_back(*c);
      }
    }
  }
}

}  // namespace syncplc
