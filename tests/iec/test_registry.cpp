// Every IEC block registers, is documented, and instantiates for every type
// of its generic class.
#include <algorithm>
#include <stdexcept>

#include "tests/iec/iec_test_util.hpp"

namespace syncplc::iectest {
namespace {

const std::vector<std::string> kExpected = {
    "TON",  "TOF",  "TP",  "R_TRIG", "F_TRIG", "CTU", "CTD", "CTUD", "SR",  "RS",   "ADD",  "SUB",
    "MUL",  "DIV",  "MOD", "ABS",    "GT",     "GE",  "EQ",  "NE",   "LE",  "LT",   "LIMIT", "MAX",
    "MIN",  "SEL",  "MOVE", "AND",   "OR",     "XOR", "NOT", "UNIT_DELAY", "BURN"};

// The IEC blocks alone (the builtin library also holds the motion blocks,
// which have their own categories, units and mandatory parameters).
const BlockRegistry& iec_registry() {
  static const BlockRegistry r = [] {
    BlockRegistry x;
    register_iec_blocks(x);
    return x;
  }();
  return r;
}

TEST(Registry, EveryBlockIsRegistered) {
  BlockRegistry r;
  register_iec_blocks(r);
  for (const auto& name : kExpected) EXPECT_NE(r.find(name), nullptr) << name;
  // and the 240 *_TO_** conversions and 16 *_TRUNC_** (test_conversion.cpp)
  EXPECT_EQ(r.all().size(), kExpected.size() + 240 + 16);
}

TEST(Registry, BuiltinLibraryHasThem) {
  for (const auto& name : kExpected) EXPECT_NE(registry().find(name), nullptr) << name;
}

TEST(Registry, RegisteringTwiceThrows) {
  BlockRegistry r;
  register_iec_blocks(r);
  EXPECT_THROW(register_iec_blocks(r), std::logic_error);
}

TEST(Registry, EveryTypeIsDocumented) {
  const std::set<std::string> categories{"IEC timers",    "IEC counters",   "IEC edge detection",
                                         "IEC bistables", "IEC arithmetic", "IEC comparison",
                                         "IEC selection", "IEC bit logic",  "execution control",
                                         "diagnostics",   "IEC type conversion"};
  for (const auto* t : iec_registry().all()) {
    SCOPED_TRACE(t->name);
    EXPECT_TRUE(categories.count(t->category)) << t->category;
    EXPECT_GE(t->doc.size(), 40u);
    EXPECT_FALSE(t->reference.empty());
    EXPECT_TRUE(t->create);
    EXPECT_FALSE(t->pins.empty());
    for (const auto& p : t->pins) {
      EXPECT_FALSE(p.doc.empty()) << p.name;
      EXPECT_TRUE(p.unit.empty()) << p.name;  // TIME carries its own unit; the rest is dimensionless
      if (p.dir == PinDir::Out) {
        EXPECT_FALSE(p.required) << p.name;
      }
    }
    for (const auto& p : t->params) EXPECT_FALSE(p.doc.empty()) << p.name;
    if (t->is_generic()) {
      ASSERT_TRUE(t->default_datatype.has_value());
      for (const auto& p : t->pins) {
        if (p.cls != TypeClass::Exact) {
          EXPECT_TRUE(in_class(*t->default_datatype, p.cls)) << p.name;
        }
      }
    }
  }
}

TEST(Registry, Categories) {
  auto cat = [](const char* n) { return registry().find(n)->category; };
  EXPECT_EQ(cat("TON"), "IEC timers");
  EXPECT_EQ(cat("CTUD"), "IEC counters");
  EXPECT_EQ(cat("R_TRIG"), "IEC edge detection");
  EXPECT_EQ(cat("RS"), "IEC bistables");
  EXPECT_EQ(cat("DIV"), "IEC arithmetic");
  EXPECT_EQ(cat("LE"), "IEC comparison");
  EXPECT_EQ(cat("SEL"), "IEC selection");
  EXPECT_EQ(cat("XOR"), "IEC bit logic");
  EXPECT_EQ(cat("UNIT_DELAY"), "execution control");
  EXPECT_EQ(cat("BURN"), "diagnostics");
}

TEST(Registry, DefaultDatatypes) {
  auto dd = [](const char* n) { return registry().find(n)->default_datatype; };
  EXPECT_EQ(dd("ADD"), IecType::LREAL);
  EXPECT_EQ(dd("DIV"), IecType::LREAL);
  EXPECT_EQ(dd("MOD"), IecType::INT);
  EXPECT_EQ(dd("CTU"), IecType::INT);
  EXPECT_EQ(dd("AND"), IecType::BOOL);
  EXPECT_EQ(dd("NOT"), IecType::BOOL);
  EXPECT_EQ(dd("GT"), IecType::LREAL);
  EXPECT_EQ(dd("UNIT_DELAY"), IecType::LREAL);
  EXPECT_FALSE(registry().find("TON")->is_generic());
  EXPECT_FALSE(registry().find("BURN")->is_generic());
}

TEST(Registry, PinClasses) {
  auto cls = [](const char* n, const char* pin) {
    const auto* t = registry().find(n);
    return t->pins[static_cast<std::size_t>(t->pin_index(pin))].cls;
  };
  EXPECT_EQ(cls("ADD", "IN1"), TypeClass::ANY_MAGNITUDE);
  EXPECT_EQ(cls("SUB", "OUT"), TypeClass::ANY_MAGNITUDE);
  EXPECT_EQ(cls("MUL", "IN3"), TypeClass::ANY_NUM);
  EXPECT_EQ(cls("DIV", "IN2"), TypeClass::ANY_NUM);
  EXPECT_EQ(cls("MOD", "OUT"), TypeClass::ANY_INT);
  EXPECT_EQ(cls("ABS", "IN"), TypeClass::ANY_NUM);
  EXPECT_EQ(cls("CTU", "PV"), TypeClass::ANY_INT);
  EXPECT_EQ(cls("CTUD", "CV"), TypeClass::ANY_INT);
  EXPECT_EQ(cls("CTU", "CU"), TypeClass::Exact);
  EXPECT_EQ(cls("GT", "IN1"), TypeClass::ANY);
  EXPECT_EQ(cls("GT", "OUT"), TypeClass::Exact);
  EXPECT_EQ(registry().find("GT")->pins[2].type, IecType::BOOL);
  EXPECT_EQ(cls("LIMIT", "MN"), TypeClass::ANY);
  EXPECT_EQ(cls("SEL", "G"), TypeClass::Exact);
  EXPECT_EQ(cls("AND", "IN8"), TypeClass::ANY_BIT);
  EXPECT_EQ(cls("UNIT_DELAY", "IN"), TypeClass::ANY);
  const auto* ton = registry().find("TON");
  EXPECT_EQ(ton->pins[static_cast<std::size_t>(ton->pin_index("PT"))].type, IecType::TIME);
  EXPECT_EQ(ton->pins[static_cast<std::size_t>(ton->pin_index("ET"))].type, IecType::TIME);
}

TEST(Registry, RequiredInputs) {
  auto req = [](const char* n, const char* pin) {
    const auto* t = registry().find(n);
    return t->pins[static_cast<std::size_t>(t->pin_index(pin))].required;
  };
  for (const char* n : {"ADD", "SUB", "MUL", "DIV", "MOD", "GT", "GE", "EQ", "NE", "LE", "LT", "MAX", "MIN",
                        "AND", "OR", "XOR"}) {
    EXPECT_TRUE(req(n, "IN1")) << n;
    EXPECT_TRUE(req(n, "IN2")) << n;
  }
  for (const char* n : {"ADD", "MUL", "MAX", "MIN", "AND", "OR", "XOR"})
    for (int i = 3; i <= 8; ++i) EXPECT_FALSE(req(n, ("IN" + std::to_string(i)).c_str())) << n << i;
  for (const char* n : {"MOVE", "NOT", "UNIT_DELAY", "LIMIT", "ABS"}) EXPECT_TRUE(req(n, "IN")) << n;
  EXPECT_FALSE(req("LIMIT", "MN"));
  EXPECT_FALSE(req("LIMIT", "MX"));
  EXPECT_TRUE(req("SEL", "G"));
  EXPECT_FALSE(req("SEL", "IN0"));
  EXPECT_FALSE(req("TON", "IN"));
  EXPECT_FALSE(req("TON", "PT"));
  EXPECT_FALSE(req("CTU", "CU"));
  EXPECT_FALSE(req("R_TRIG", "CLK"));
  EXPECT_FALSE(req("BURN", "EXEC"));
}

TEST(Registry, EveryGenericBlockInstantiatesForEveryTypeOfItsClass) {
  for (const auto* t : iec_registry().all()) {
    std::optional<TypeClass> cls;
    for (const auto& p : t->pins)
      if (p.cls != TypeClass::Exact) cls = p.cls;
    for (int i = 0; i < kIecTypeCount; ++i) {
      const auto type = static_cast<IecType>(i);
      if (!cls && type != IecType::LREAL) continue;
      BlockHarness h(iec_registry(), t->name, opts(type));
      const bool admitted = !cls || in_class(type, *cls);
      EXPECT_EQ(h.ok(), admitted) << t->name << " " << type_name(type) << ": " << errors_of(h);
      if (h.ok()) h.scans(3);  // zero inputs run cleanly (DIV/MOD just report division by zero)
    }
  }
}

}  // namespace
}  // namespace syncplc::iectest
