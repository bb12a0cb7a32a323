// The one way to declare a block's pins: a pin by name and type, then named
// steps instead of positional "", "", true arguments.
//
//   input("IN", IecType::LREAL).unit("m").doc("measured position").required()
//   input("IN1", TypeClass::ANY_NUM).doc("operand 1")       // generic pin
//   output("OUT", IecType::BOOL).doc("TRUE once ET >= PT")
//   input("w", IecType::LREAL).array("n").init("1")          // ARRAY[1..n]
#pragma once

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

}  // namespace syncplc
