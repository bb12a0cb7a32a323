// IEC 61131-3 direct addresses (%IX0.0, %QW3, %MD10, %ML2 ...). Addressing is
// by size as in CODESYS: %MWn starts at byte 2n, %MDn at byte 4n, %MLn at 8n,
// so %MW2 and %MD1 overlap.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "runtime/core/iec_type.hpp"

namespace syncplc {

enum class Area : char { Input = 'I', Output = 'Q', Memory = 'M' };
enum class AddrSize : char { Bit = 'X', Byte = 'B', Word = 'W', Double = 'D', Long = 'L' };

struct DirectAddress {
  Area area = Area::Memory;
  AddrSize size = AddrSize::Word;
  std::uint32_t index = 0;  // bit: the byte number; otherwise the element number
  std::uint8_t bit = 0;     // bit addresses only

  int size_bits() const;
  // First bit and one-past-last bit occupied by `count` consecutive elements.
  std::uint64_t first_bit() const;
  std::uint64_t end_bit(std::uint32_t count) const;
  std::string text() const;
};

std::optional<DirectAddress> parse_direct_address(std::string_view s, std::string* error);
// Whether a tag of type t may sit at an address of this size (%IX: BOOL; %IW:
// 16-bit types; ...). Empty on success, otherwise the reason.
std::string check_address_type(const DirectAddress& a, IecType t);
bool overlaps(const DirectAddress& a, std::uint32_t na, const DirectAddress& b, std::uint32_t nb);

}  // namespace syncplc
