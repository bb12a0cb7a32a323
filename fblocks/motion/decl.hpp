// Internal: how the motion blocks declare their pins and parameters, one
// place for all of fblocks/motion.
#pragma once

#include <optional>
#include <string>
#include <utility>

#include "runtime/core/block.hpp"

namespace syncplc::motion {

// A pin of an exact IEC type. `length_param` names the integer parameter that
// makes it an array pin (ARRAY[1..n]); "" for a scalar.
inline PinDecl pin(std::string name, PinDir dir, IecType type, std::string unit, std::string doc,
                   std::string init = {}, std::string length_param = {}, bool required = false) {
  PinDecl p;
  p.name = std::move(name);
  p.dir = dir;
  p.type = type;
  p.unit = std::move(unit);
  p.doc = std::move(doc);
  p.init = std::move(init);
  p.length_param = std::move(length_param);
  p.required = required;
  return p;
}

inline ParamDecl param(std::string name, IecType type, std::string def, std::optional<double> min,
                       std::optional<double> max, std::string unit, std::string doc) {
  ParamDecl p;
  p.name = std::move(name);
  p.type = type;
  p.default_value = std::move(def);
  p.min = min;
  p.max = max;
  p.unit = std::move(unit);
  p.doc = std::move(doc);
  return p;
}

// A tunable parameter (ParamDecl::tunable): it may change while the block
// runs, through an online change (Block::retune_from) or its tuning input
// <name>_in (Block::tune), bumplessly.
inline ParamDecl tunable(ParamDecl p) {
  p.tunable = true;
  return p;
}

}  // namespace syncplc::motion
