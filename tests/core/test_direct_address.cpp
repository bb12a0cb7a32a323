// Direct addresses: parsing, text round trip, the CODESYS overlap rule, and
// which types may sit at which size.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "runtime/core/direct_address.hpp"

namespace syncplc {
namespace {

using ::testing::HasSubstr;

DirectAddress addr(const std::string& s) {
  std::string err;
  auto a = parse_direct_address(s, &err);
  EXPECT_TRUE(a.has_value()) << s << ": " << err;
  return a.value_or(DirectAddress{});
}

std::string bad(const std::string& s) {
  std::string err;
  EXPECT_FALSE(parse_direct_address(s, &err).has_value()) << s;
  return err;
}

TEST(DirectAddress, Parse) {
  DirectAddress a = addr("%IX0.3");
  EXPECT_EQ(a.area, Area::Input);
  EXPECT_EQ(a.size, AddrSize::Bit);
  EXPECT_EQ(a.index, 0u);
  EXPECT_EQ(a.bit, 3);
  DirectAddress w = addr("%QW3");
  EXPECT_EQ(w.area, Area::Output);
  EXPECT_EQ(w.size, AddrSize::Word);
  EXPECT_EQ(w.index, 3u);
  EXPECT_EQ(addr("%MD10").size, AddrSize::Double);
  EXPECT_EQ(addr("%ML2").size, AddrSize::Long);
  EXPECT_EQ(addr("%IB7").size, AddrSize::Byte);
  EXPECT_EQ(addr("%I1.7").size, AddrSize::Bit);  // %I1.7 is short for %IX1.7
  EXPECT_EQ(addr("%qx2.1").area, Area::Output);  // case-insensitive
  EXPECT_EQ(addr("%MW65535").index, 65535u);
}

TEST(DirectAddress, TextRoundTrip) {
  for (const char* s : {"%IX0.0", "%IX12.7", "%QX1.1", "%MX0.0", "%IB3", "%QW3", "%MW2", "%MD1", "%ML2", "%IL0"})
    EXPECT_EQ(addr(s).text(), s);
  EXPECT_EQ(addr("%I1.7").text(), "%IX1.7");
  EXPECT_EQ(addr("%mw4").text(), "%MW4");
  for (const char* s : {"%IX3.5", "%QD9", "%MB100"}) EXPECT_EQ(addr(addr(s).text()).text(), s);
}

TEST(DirectAddress, Errors) {
  EXPECT_EQ(bad("IX0.0"), "bad direct address 'IX0.0': must start with %, e.g. %IX0.0, %QW3, %MD10");
  EXPECT_EQ(bad("%I"), "bad direct address '%I': must start with %, e.g. %IX0.0, %QW3, %MD10");
  EXPECT_EQ(bad("%XW3"), "bad direct address '%XW3': area must be I, Q or M");
  EXPECT_EQ(bad("%IZ3"), "bad direct address '%IZ3': size must be X, B, W, D or L");
  EXPECT_EQ(bad("%IX0"), "bad direct address '%IX0': a bit address needs .bit, e.g. %IX0.3");
  EXPECT_EQ(bad("%IX0.8"), "bad direct address '%IX0.8': bit must be 0..7");
  EXPECT_EQ(bad("%IX0.x"), "bad direct address '%IX0.x': bit must be 0..7");
  EXPECT_EQ(bad("%IW0.1"), "bad direct address '%IW0.1': only bit addresses (X) take .bit");
  EXPECT_EQ(bad("%IW"), "bad direct address '%IW': missing number");
  EXPECT_EQ(bad("%IWx"), "bad direct address '%IWx': bad number");
  EXPECT_EQ(bad("%IW-1"), "bad direct address '%IW-1': bad number");
}

TEST(DirectAddress, BitsOccupied) {
  EXPECT_EQ(addr("%IX0.3").first_bit(), 3u);
  EXPECT_EQ(addr("%IX2.1").first_bit(), 17u);
  EXPECT_EQ(addr("%IB2").first_bit(), 16u);
  EXPECT_EQ(addr("%MW2").first_bit(), 32u);   // byte 4
  EXPECT_EQ(addr("%MD1").first_bit(), 32u);   // byte 4 too
  EXPECT_EQ(addr("%ML1").first_bit(), 64u);   // byte 8
  EXPECT_EQ(addr("%MW2").end_bit(1), 48u);
  EXPECT_EQ(addr("%MW2").end_bit(3), 80u);
  EXPECT_EQ(addr("%IX0.0").end_bit(1), 1u);
  EXPECT_EQ(addr("%MW2").size_bits(), 16);
}

TEST(DirectAddress, CodesysOverlapRule) {
  auto ov = [](const char* a, std::uint32_t na, const char* b, std::uint32_t nb) {
    return overlaps(addr(a), na, addr(b), nb);
  };
  EXPECT_TRUE(ov("%MW2", 1, "%MD1", 1));   // bytes 4-5 inside bytes 4-7
  EXPECT_TRUE(ov("%MD1", 1, "%MW3", 1));   // bytes 6-7
  EXPECT_FALSE(ov("%MW1", 1, "%MD1", 1));  // bytes 2-3 vs 4-7
  EXPECT_FALSE(ov("%MW4", 1, "%MD1", 1));  // bytes 8-9
  EXPECT_TRUE(ov("%ML1", 1, "%MB15", 1));
  EXPECT_FALSE(ov("%ML1", 1, "%MB16", 1));
  EXPECT_TRUE(ov("%MW2", 1, "%MW2", 1));
  // Bit against byte: %IX0.3 is a bit of %IB0, not of %IB1.
  EXPECT_TRUE(ov("%IX0.3", 1, "%IB0", 1));
  EXPECT_FALSE(ov("%IX1.0", 1, "%IB0", 1));
  EXPECT_TRUE(ov("%IX1.0", 1, "%IW0", 1));
  EXPECT_FALSE(ov("%IX0.3", 1, "%IX0.4", 1));
  EXPECT_TRUE(ov("%QX1.1", 1, "%QX1.1", 1));
  // Areas are separate.
  EXPECT_FALSE(ov("%IW0", 1, "%QW0", 1));
  EXPECT_FALSE(ov("%MX0.0", 1, "%IX0.0", 1));
  // Arrays occupy count consecutive elements.
  EXPECT_TRUE(ov("%MW10", 4, "%MW13", 1));
  EXPECT_FALSE(ov("%MW10", 4, "%MW14", 1));
  EXPECT_TRUE(ov("%MD5", 1, "%MW10", 4));  // bytes 20-23 vs 20-27
  EXPECT_TRUE(ov("%IX0.0", 8, "%IX0.7", 1));
  EXPECT_FALSE(ov("%IX0.0", 8, "%IX1.0", 1));
}

TEST(DirectAddress, TypeMustFitTheSize) {
  EXPECT_EQ(check_address_type(addr("%IX0.0"), IecType::BOOL), "");
  EXPECT_EQ(check_address_type(addr("%IB0"), IecType::BYTE), "");
  EXPECT_EQ(check_address_type(addr("%IB0"), IecType::SINT), "");
  EXPECT_EQ(check_address_type(addr("%IB0"), IecType::USINT), "");
  EXPECT_EQ(check_address_type(addr("%IW0"), IecType::INT), "");
  EXPECT_EQ(check_address_type(addr("%IW0"), IecType::UINT), "");
  EXPECT_EQ(check_address_type(addr("%IW0"), IecType::WORD), "");
  EXPECT_EQ(check_address_type(addr("%MD0"), IecType::REAL), "");
  EXPECT_EQ(check_address_type(addr("%MD0"), IecType::DINT), "");
  EXPECT_EQ(check_address_type(addr("%ML0"), IecType::LREAL), "");
  EXPECT_EQ(check_address_type(addr("%ML0"), IecType::TIME), "");
  EXPECT_EQ(check_address_type(addr("%ML0"), IecType::LWORD), "");
  EXPECT_EQ(check_address_type(addr("%IW0"), IecType::BOOL), "a BOOL cannot sit at %IW0 (16-bit address; use X)");
  EXPECT_EQ(check_address_type(addr("%IB0"), IecType::BOOL), "a BOOL cannot sit at %IB0 (8-bit address; use X)");
  EXPECT_EQ(check_address_type(addr("%QX0.0"), IecType::INT), "a INT cannot sit at %QX0.0 (1-bit address; use W)");
  EXPECT_EQ(check_address_type(addr("%MD4"), IecType::LREAL), "a LREAL cannot sit at %MD4 (32-bit address; use L)");
  EXPECT_THAT(check_address_type(addr("%MW0"), IecType::BYTE), HasSubstr("use B"));
  EXPECT_THAT(check_address_type(addr("%MW0"), IecType::DINT), HasSubstr("use D"));
}

}  // namespace
}  // namespace syncplc
