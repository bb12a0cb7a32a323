// The one way to declare a block's pins and parameters: a pin or parameter by
// name and type, then named steps instead of positional "", "", true arguments.
//
//   input("IN", IecType::LREAL).unit("m").doc("measured position").required()
//   input("IN1", TypeClass::ANY_NUM).doc("operand 1")       // generic pin
//   output("OUT", IecType::BOOL).doc("TRUE once ET >= PT")
//   input("w", IecType::LREAL).array("n").init("1")          // ARRAY[1..n]
//   parameter("kp", IecType::LREAL).init("1").min(0).unit("1/s").tunable().doc("gain")
#pragma once

#include <optional>
#include <string>
#include <utility>

#include "runtime/core/block.hpp"

namespace syncplc {

class Pin {
 public:
  Pin(std::string name, PinDir dir, IecType type) {
    d_.name = std::move(name);
    d_.dir = dir;
    d_.type = type;
  }
  Pin(std::string name, PinDir dir, TypeClass cls) {
    d_.name = std::move(name);
    d_.dir = dir;
    d_.cls = cls;
  }
  Pin& unit(std::string u) { d_.unit = std::move(u); return *this; }
  Pin& doc(std::string text) { d_.doc = std::move(text); return *this; }
  Pin& required(bool r = true) { d_.required = r; return *this; }
  Pin& init(std::string value) { d_.init = std::move(value); return *this; }
  Pin& array(std::string length_param) { d_.length_param = std::move(length_param); return *this; }
  operator PinDecl() const { return d_; }

 private:
  PinDecl d_;
};

inline Pin input(std::string name, IecType type) { return Pin(std::move(name), PinDir::In, type); }
inline Pin input(std::string name, TypeClass cls) { return Pin(std::move(name), PinDir::In, cls); }
inline Pin output(std::string name, IecType type) { return Pin(std::move(name), PinDir::Out, type); }
inline Pin output(std::string name, TypeClass cls) { return Pin(std::move(name), PinDir::Out, cls); }

// A parameter without init() is mandatory: every instance must set it.
class Param {
 public:
  Param(std::string name, IecType type) {
    d_.name = std::move(name);
    d_.type = type;
  }
  Param& init(std::string value) { d_.default_value = std::move(value); return *this; }
  Param& min(double v) { d_.min = v; return *this; }  // inclusive, in unit()
  Param& max(double v) { d_.max = v; return *this; }
  Param& unit(std::string u) { d_.unit = std::move(u); return *this; }
  Param& doc(std::string text) { d_.doc = std::move(text); return *this; }
  // May change while the block runs (ParamDecl::tunable): through an online
  // change (Block::retune_from) or its tuning input <name>_in (Block::tune).
  Param& tunable(bool t = true) { d_.tunable = t; return *this; }
  operator ParamDecl() const { return d_; }

 private:
  ParamDecl d_;
};

inline Param parameter(std::string name, IecType type) { return Param(std::move(name), type); }

}  // namespace syncplc
