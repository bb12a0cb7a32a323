#include "runtime/core/direct_address.hpp"

#include <cctype>
#include <charconv>

namespace syncplc {

int DirectAddress::size_bits() const {
  switch (size) {
    case AddrSize::Bit: return 1;
    case AddrSize::Byte: return 8;
    case AddrSize::Word: return 16;
    case AddrSize::Double: return 32;
    case AddrSize::Long: return 64;
  }
  return 0;
}

std::uint64_t DirectAddress::first_bit() const {
  if (size == AddrSize::Bit) return std::uint64_t{index} * 8 + bit;
  return std::uint64_t{index} * static_cast<std::uint64_t>(size_bits());
}

std::uint64_t DirectAddress::end_bit(std::uint32_t count) const {
  return first_bit() + std::uint64_t{count} * static_cast<std::uint64_t>(size_bits());
}

std::string DirectAddress::text() const {
  std::string s = "%";
  s += static_cast<char>(area);
  s += static_cast<char>(size);
  s += std::to_string(index);
  if (size == AddrSize::Bit) s += "." + std::to_string(bit);
  return s;
}

std::optional<DirectAddress> parse_direct_address(std::string_view s, std::string* error) {
  auto bad = [&](const std::string& why) -> std::optional<DirectAddress> {
    if (error) *error = "bad direct address '" + std::string(s) + "': " + why;
    return std::nullopt;
  };
  if (s.size() < 3 || s[0] != '%') return bad("must start with %, e.g. %IX0.0, %QW3, %MD10");
  DirectAddress a;
  char ar = static_cast<char>(std::toupper(static_cast<unsigned char>(s[1])));
  if (ar == 'I') a.area = Area::Input;
  else if (ar == 'Q') a.area = Area::Output;
  else if (ar == 'M') a.area = Area::Memory;
  else return bad("area must be I, Q or M");
  std::size_t i = 2;
  char sz = static_cast<char>(std::toupper(static_cast<unsigned char>(s[2])));
  if (std::isdigit(static_cast<unsigned char>(sz))) {
    a.size = AddrSize::Bit;  // %I0.0 is short for %IX0.0
  } else {
    switch (sz) {
      case 'X': a.size = AddrSize::Bit; break;
      case 'B': a.size = AddrSize::Byte; break;
      case 'W': a.size = AddrSize::Word; break;
      case 'D': a.size = AddrSize::Double; break;
      case 'L': a.size = AddrSize::Long; break;
      default: return bad("size must be X, B, W, D or L");
    }
    i = 3;
  }
  std::string_view rest = s.substr(i);
  std::size_t dot = rest.find('.');
  std::string_view num = rest.substr(0, dot);
  if (num.empty()) return bad("missing number");
  auto [p, ec] = std::from_chars(num.data(), num.data() + num.size(), a.index);
  if (ec != std::errc() || p != num.data() + num.size()) return bad("bad number");
  if (a.size == AddrSize::Bit) {
    if (dot == std::string_view::npos) return bad("a bit address needs .bit, e.g. %IX0.3");
    std::string_view b = rest.substr(dot + 1);
    unsigned bit = 99;
    auto [p2, ec2] = std::from_chars(b.data(), b.data() + b.size(), bit);
    if (ec2 != std::errc() || p2 != b.data() + b.size() || bit > 7) return bad("bit must be 0..7");
    a.bit = static_cast<std::uint8_t>(bit);
  } else if (dot != std::string_view::npos) {
    return bad("only bit addresses (X) take .bit");
  }
  return a;
}

std::string check_address_type(const DirectAddress& a, IecType t) {
  int w = bit_width(t);
  if (t == IecType::BOOL && a.size == AddrSize::Bit) return {};
  if (t != IecType::BOOL && w == a.size_bits()) return {};
  return "a " + std::string(type_name(t)) + " cannot sit at " + a.text() + " (" + std::to_string(a.size_bits()) +
         "-bit address; use " +
         (t == IecType::BOOL ? std::string("X") : w == 8 ? "B" : w == 16 ? "W" : w == 32 ? "D" : "L") + ")";
}

bool overlaps(const DirectAddress& a, std::uint32_t na, const DirectAddress& b, std::uint32_t nb) {
  if (a.area != b.area) return false;
  return a.first_bit() < b.end_bit(nb) && b.first_bit() < a.end_bit(na);
}

}  // namespace syncplc
