// Live-value subscriptions (runtime/web/subscriptions.hpp): references added
// and dropped as views open and close, one stream at a time, owned by the
// session that made them, bounded in number and size, ended a minute after
// their last stream.
#include <gtest/gtest.h>

#include "runtime/web/subscriptions.hpp"

namespace syncplc::web {
namespace subscriptions_test {

constexpr std::int64_t kSecond = 1'000'000'000;

std::vector<std::string> many(std::size_t n, const std::string& prefix = "a_tag_with_a_name_of_forty_one_characters") {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < n; ++i) out.push_back(prefix + std::to_string(i));
  return out;
}

TEST(Subscriptions, AnyNumberOfRefsAddedAndDroppedAsViewsOpenAndClose) {
  Subscriptions subs;
  std::string error;
  int status = 0;
  // 300 references of 41+ characters: more than a URL holds (8 KiB) and than /stream takes (256).
  const auto s = subs.create("tok", 10, many(300), 0, &error, &status);
  ASSERT_TRUE(s) << error;
  EXPECT_EQ(s->refs.size(), 300u);
  EXPECT_EQ(s->id.size(), 32u) << "128 random bits";
  const auto ch = subs.change(s->id, "tok", {"speed", "a_tag_with_a_name_of_forty_one_characters0"}, many(100), kSecond);
  ASSERT_TRUE(ch.ok) << ch.error;
  EXPECT_EQ(ch.added, std::vector<std::string>{"speed"}) << "one already there is not added twice";
  EXPECT_EQ(ch.dropped.size(), 100u);
  const auto now = subs.get(s->id, "tok");
  ASSERT_TRUE(now);
  EXPECT_EQ(now->refs.size(), 201u);
  EXPECT_EQ(now->refs.back(), "speed");
  EXPECT_GT(now->version, s->version);
  EXPECT_EQ(subs.total_refs(), 201u);

  // A stream sees the change at its next poll, once.
  const std::uint64_t a = subs.attach(s->id, "tok", kSecond);
  ASSERT_NE(a, 0u);
  std::uint64_t version = 0;
  std::vector<std::string> refs;
  bool changed = false;
  ASSERT_TRUE(subs.poll(s->id, a, &version, &refs, &changed, kSecond));
  EXPECT_TRUE(changed);
  EXPECT_EQ(refs.size(), 201u);
  ASSERT_TRUE(subs.poll(s->id, a, &version, &refs, &changed, kSecond));
  EXPECT_FALSE(changed);
  ASSERT_TRUE(subs.change(s->id, "tok", {}, {"speed"}, kSecond).ok);
  ASSERT_TRUE(subs.poll(s->id, a, &version, &refs, &changed, kSecond));
  EXPECT_TRUE(changed);
  EXPECT_EQ(refs.size(), 200u);
}

TEST(Subscriptions, OwnedByTheSessionThatMadeThem) {
  Subscriptions subs;
  std::string error;
  int status = 0;
  const auto s = subs.create("tok-a", 10, {"x"}, 0, &error, &status);
  ASSERT_TRUE(s);
  EXPECT_FALSE(subs.get(s->id, "tok-b"));
  EXPECT_FALSE(subs.get(s->id, "")) << "not an anonymous reader's";
  EXPECT_EQ(subs.change(s->id, "tok-b", {"y"}, {}, 0).status, 404);
  EXPECT_EQ(subs.attach(s->id, "tok-b", 0), 0u);
  EXPECT_FALSE(subs.remove(s->id, "tok-b"));
  EXPECT_TRUE(subs.get(s->id, "tok-a"));
  // Logout ends them.
  subs.remove_owner("tok-a");
  EXPECT_FALSE(subs.get(s->id, "tok-a"));
  EXPECT_EQ(subs.total_refs(), 0u);
}

TEST(Subscriptions, TheNewestStreamWinsAndAnIdleOneEndsAfterAMinute) {
  Subscriptions subs;
  std::string error;
  int status = 0;
  const auto s = subs.create("", 10, {"x"}, 0, &error, &status);
  ASSERT_TRUE(s);
  const std::uint64_t first = subs.attach(s->id, "", 0);
  const std::uint64_t second = subs.attach(s->id, "", 0);  // the browser reconnected
  std::uint64_t version = 0;
  std::vector<std::string> refs;
  bool changed = false;
  EXPECT_FALSE(subs.poll(s->id, first, &version, &refs, &changed, 0)) << "the older stream ends";
  EXPECT_TRUE(subs.poll(s->id, second, &version, &refs, &changed, 0));
  subs.detach(s->id, first, 0);  // the older stream's end does not detach the newer
  // While a stream holds it, no expiry, however long.
  std::string e2;
  ASSERT_TRUE(subs.create("", 10, {"y"}, 10 * 60 * kSecond, &e2, &status));
  EXPECT_TRUE(subs.get(s->id, ""));
  subs.detach(s->id, second, 10 * 60 * kSecond);
  // A minute without a stream: gone at the next look.
  ASSERT_TRUE(subs.create("", 10, {"z"}, 11 * 60 * kSecond - 1, &e2, &status));
  EXPECT_TRUE(subs.get(s->id, ""));
  ASSERT_TRUE(subs.create("", 10, {"w"}, 11 * 60 * kSecond + 1, &e2, &status));
  EXPECT_FALSE(subs.get(s->id, ""));
}

TEST(Subscriptions, BoundedInNumberAndSize) {
  SubscriptionLimits limits;
  limits.max_subscriptions = 3;
  limits.max_refs = 10;
  limits.max_total_refs = 25;
  limits.max_ref_bytes = 16;
  Subscriptions subs(limits);
  std::string error;
  int status = 0;
  EXPECT_FALSE(subs.create("", 10, many(11, "r"), 0, &error, &status));
  EXPECT_EQ(status, 400);
  EXPECT_FALSE(subs.create("", 10, {std::string(17, 'x')}, 0, &error, &status));
  EXPECT_EQ(status, 400);
  EXPECT_NE(error.find("16 bytes"), std::string::npos) << error;
  EXPECT_FALSE(subs.create("", 10, {""}, 0, &error, &status));
  const auto a = subs.create("", 10, many(10, "a"), 0, &error, &status);
  const auto b = subs.create("", 10, many(10, "b"), 0, &error, &status);
  ASSERT_TRUE(a && b);
  EXPECT_FALSE(subs.create("", 10, many(6, "c"), 0, &error, &status)) << "25 references in all";
  EXPECT_EQ(status, 503);
  const auto c = subs.create("", 10, many(5, "c"), 0, &error, &status);
  ASSERT_TRUE(c);
  EXPECT_FALSE(subs.create("", 10, {}, 0, &error, &status)) << "three subscriptions at most";
  EXPECT_EQ(status, 503);
  // A change past a bound changes nothing.
  const auto over = subs.change(c->id, "", many(4, "d"), {}, 0);  // 9 in c, 29 in all
  EXPECT_FALSE(over.ok);
  EXPECT_EQ(over.status, 503);
  EXPECT_EQ(subs.get(c->id, "")->refs.size(), 5u);
  const auto too_many = subs.change(a->id, "", {"z"}, {}, 0);
  EXPECT_EQ(too_many.status, 400);
  EXPECT_EQ(subs.total_refs(), 25u);
  // Dropping makes room.
  ASSERT_TRUE(subs.change(a->id, "", {"z"}, {"a0", "a1"}, 0).ok);
  EXPECT_EQ(subs.total_refs(), 24u);
  EXPECT_TRUE(subs.remove(b->id, ""));
  EXPECT_EQ(subs.total_refs(), 14u);
  EXPECT_EQ(subs.size(), 2u);
}

}  // namespace subscriptions_test
}  // namespace syncplc::web
