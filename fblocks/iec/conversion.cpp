// IEC 61131-3 type conversion functions *_TO_** between every pair of
// elementary types, and the truncations REAL_TRUNC_** / LREAL_TRUNC_**,
// generated from the type list (IEC 61131-3 ed. 2, 2.5.1.5.1, Table 22; the
// typed *_TRUNC_** names are those of ed. 3).
//
// The conversion rules and their one implementation are in
// runtime/core/iec_convert.hpp (the ST VM uses the same); here a saturated
// result raises a block-fault event "conversion out of range" with the value.
#include "fblocks/iec/common.hpp"
#include "runtime/core/iec_convert.hpp"

namespace syncplc::iec {
namespace {

// The conversion math is runtime/core/iec_convert.* (shared with the ST VM).
class Conversion final : public Block {
 public:
  Conversion(IecType s, ConvertFn f) : s_(s), f_(f) {}
  void execute(ScanContext& ctx) noexcept override {
    bool out_of_range = false;
    const Cell in = *pin_cell(0);
    *pin_cell(1) = f_(in, &out_of_range);
    if (out_of_range) ctx.fault("conversion out of range", cell_as_double(s_, in));
  }

 private:
  IecType s_;
  ConvertFn f_;
};

constexpr IecType kAll[] = {IecType::BOOL,  IecType::SINT,  IecType::INT,   IecType::DINT,
                            IecType::LINT,  IecType::USINT, IecType::UINT,  IecType::UDINT,
                            IecType::ULINT, IecType::BYTE,  IecType::WORD,  IecType::DWORD,
                            IecType::LWORD, IecType::REAL,  IecType::LREAL, IecType::TIME};

std::string rule_text(IecType s, IecType d, bool trunc) {
  const auto sn = std::string(type_name(s)), dn = std::string(type_name(d));
  std::string t = "OUT := IN converted from " + sn + " to " + dn + ". ";
  if (trunc) return t + "Rounds toward zero (IEC 61131-3 Table 22 note c); a result outside the range of " + dn +
                    " is saturated to its minimum or maximum and raises a block-fault event \"conversion out of "
                    "range\".";
  if (d == IecType::BOOL) return t + "TRUE when IN is not zero.";
  if (s == IecType::BOOL) return t + "FALSE gives 0, TRUE gives 1" + (d == IecType::TIME ? " ms." : ".");
  if (is_bit_string(d))
    return t + (is_real(s) ? "IN is rounded to nearest (ties to even); a value outside 0 .. the largest " + dn +
                                 " is saturated and raises a block-fault event \"conversion out of range\"."
                           : "The low bits of IN's two's-complement pattern" +
                                 std::string(s == IecType::TIME ? ", IN counted in milliseconds" : "") +
                                 " (no fault).");
  std::string r;
  if (s == IecType::TIME) r += "IN counted in milliseconds. ";
  if (d == IecType::TIME) r += "IN counts milliseconds. ";
  if (is_bit_string(s) && is_integer(d) && bit_width(s) == bit_width(d))
    return t + "The bits of IN, reinterpreted (16#FF.. gives -1 for a signed type; no fault).";
  if ((is_real(s) || s == IecType::TIME) && is_integer(d))
    r += "Rounds to nearest, ties to even (IEC 60559, Table 22 note b: 2.5 -> 2, -1.5 -> -2; use " +
         std::string(is_real(s) ? sn + "_TRUNC_" + dn : "a TRUNC") + " to truncate). ";
  if (is_bit_string(s)) r += "IN counts as an unsigned number. ";
  if (d == IecType::LREAL || (d == IecType::REAL && s != IecType::LREAL)) return t + r + "Never out of range.";
  return t + r + "A value outside the range of " + dn +
         " is saturated to its minimum or maximum and raises a block-fault event \"conversion out of range\" "
         "(IEC leaves it implementation-defined; CODESYS keeps the low bits).";
}

BlockTypeInfo info(IecType s, IecType d, bool trunc) {
  BlockTypeInfo t;
  t.name = std::string(type_name(s)) + (trunc ? "_TRUNC_" : "_TO_") + std::string(type_name(d));
  t.category = "IEC type conversion";
  t.doc = rule_text(s, d, trunc);
  t.reference = trunc ? "IEC 61131-3 standard function, 2.5.1.5.1 Table 22 note c (typed *_TRUNC_** of ed. 3)"
                      : "IEC 61131-3 standard function, 2.5.1.5.1 Table 22 (type conversion), notes a and b";
  t.pins = {input("IN", s).required().doc("value to convert"),
            output("OUT", d).doc("IN as " + std::string(type_name(d)))};
  return t;
}

}  // namespace

void register_conversions(BlockRegistry& r) {
  for (IecType s : kAll)
    for (IecType d : kAll) {
      if (s == d) continue;
      for (bool trunc : {false, true}) {
        if (trunc && !(is_real(s) && is_integer(d))) continue;
        BlockTypeInfo t = info(s, d, trunc);
        t.create = [s, d, trunc](BlockSetup&) -> std::unique_ptr<Block> {
          return std::make_unique<Conversion>(s, conversion_fn(s, d, trunc));
        };
        r.add(std::move(t));
      }
    }
}

}  // namespace syncplc::iec
