// "Did you mean …?" (runtime/core/closest_name.hpp): the distance and its
// early stop, which must not change which name is suggested.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "runtime/core/closest_name.hpp"

namespace syncplc {
namespace {

TEST(ClosestName, DistanceIsLevenshteinIgnoringCase) {
  EXPECT_EQ(name_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(name_distance("END_IF", "end_if"), 0u);
  EXPECT_EQ(name_distance("", "abc"), 3u);
  EXPECT_EQ(name_distance("abc", ""), 3u);
  EXPECT_EQ(name_distance("ELSIF", "ELSEIF"), 1u);
}

TEST(ClosestName, TheLimitStopsEarlyButNeverUnderstates) {
  // Lengths four apart: at least 4, so at the limit 3 the answer is the limit.
  EXPECT_EQ(name_distance("abcd", "abcdefgh", 3), 3u);
  EXPECT_EQ(name_distance("abcd", "abcdefgh", 5), 4u);
  // Every row past the limit: stops, and says the limit.
  EXPECT_EQ(name_distance("aaaaaaaa", "bbbbbbbb", 2), 2u);
  EXPECT_EQ(name_distance("aaaaaaaa", "bbbbbbbb"), 8u);
  // Under the limit it is the exact distance.
  EXPECT_EQ(name_distance("kitten", "sitting", 4), 3u);
}

TEST(ClosestName, LongNamesAreMeasuredToo) {
  const std::string a(300, 'x'), b = std::string(299, 'x') + "y";
  EXPECT_EQ(name_distance(a, b), 1u);
  EXPECT_EQ(name_distance(a, std::string(150, 'x')), 150u);
}

TEST(ClosestName, TheClosestWithinAThirdIsSuggested) {
  const std::vector<std::string> names = {"END_IF", "END_FOR", "END_WHILE", "ELSIF", "counter", "Counter2"};
  EXPECT_EQ(closest_name("END_FI", names), "END_IF");
  EXPECT_EQ(closest_name("end_whle", names), "END_WHILE");
  EXPECT_EQ(closest_name("COUNTER", names), "counter");  // case only: closest of all
  EXPECT_EQ(closest_name("xyz", names), "");
  EXPECT_EQ(closest_name(std::string(65, 'E'), names), "");
}

}  // namespace
}  // namespace syncplc
