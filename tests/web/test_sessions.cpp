// What a login leaves behind (runtime/web/sessions.hpp): session tokens and
// their expiry, the login limiter's refusals and its memory bound, the gate
// on concurrent password hashes. Times are chosen by the tests.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <thread>
#include <vector>

#include "runtime/web/sessions.hpp"

namespace syncplc::web {
namespace {

constexpr std::int64_t kS = 1'000'000'000;
constexpr std::int64_t kMin = 60 * kS;
constexpr std::int64_t kT0 = 1'000 * kS;  // any start of the monotonic clock

const User kAlice{"alice", Role::Engineer, 0, 0x5a17};
const User kBob{"bob", Role::Operator, 0, 0x0b0b};

// ---------------------------------------------------------------- Sessions

TEST(Sessions, ATokenIs43CharactersOfBase64urlAndChecksAsItsUser) {
  Sessions s;
  const std::string token = s.issue(kAlice, kT0);
  EXPECT_EQ(token.size(), 43u) << "32 bytes, base64url, no padding";
  EXPECT_TRUE(std::all_of(token.begin(), token.end(),
                          [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_'; }))
      << token;
  EXPECT_NE(s.issue(kAlice, kT0), token) << "each login its own token";
  auto session = s.check(token, kT0 + 5 * kS);
  ASSERT_TRUE(session);
  EXPECT_EQ(session->user, "alice");
  EXPECT_EQ(session->role, Role::Engineer);
  EXPECT_EQ(session->stamp, 0x5a17) << "the user's credential stamp at the login, to compare with the table's";
  EXPECT_EQ(session->issued_ns, kT0);
  EXPECT_EQ(session->last_ns, kT0 + 5 * kS) << "a check is a use";
  EXPECT_EQ(s.size(), 2u);
}

TEST(Sessions, OnlyTheExactTokenChecksNotOneThatDiffersByOneCharacter) {
  Sessions s;
  const std::string token = s.issue(kAlice, kT0);
  for (std::size_t i : {std::size_t{0}, std::size_t{21}, std::size_t{42}}) {
    std::string other = token;
    other[i] = other[i] == 'A' ? 'B' : 'A';
    EXPECT_FALSE(s.check(other, kT0)) << other;
  }
  EXPECT_FALSE(s.check(token.substr(0, 42), kT0));
  EXPECT_FALSE(s.check(token + "A", kT0));
  EXPECT_FALSE(s.check("", kT0));
  EXPECT_TRUE(s.check(token, kT0)) << "the failed checks did not harm it";
  Sessions another;
  EXPECT_FALSE(another.check(token, kT0)) << "a token belongs to the Sessions that issued it";
}

TEST(Sessions, EndsAfterThirtyMinutesWithoutARequest) {
  Sessions s;
  const std::string token = s.issue(kAlice, kT0);
  ASSERT_TRUE(s.check(token, kT0 + 30 * kMin - 1));
  ASSERT_TRUE(s.check(token, kT0 + 60 * kMin - 2)) << "each use starts the idle time again";
  EXPECT_FALSE(s.check(token, kT0 + 90 * kMin - 2)) << "30 min after the last use";
  EXPECT_EQ(s.size(), 0u) << "an expired session is forgotten";
  EXPECT_FALSE(s.check(token, kT0 + 90 * kMin - 2));
}

TEST(Sessions, EndsEightHoursAfterTheLoginHoweverOftenItIsUsed) {
  Sessions s;
  const std::string token = s.issue(kAlice, kT0);
  std::int64_t t = kT0;
  for (; t + 10 * kMin < kT0 + 8 * 60 * kMin; t += 10 * kMin) ASSERT_TRUE(s.check(token, t + 10 * kMin)) << t;
  EXPECT_FALSE(s.check(token, kT0 + 8 * 60 * kMin));
}

TEST(Sessions, IdleTimeAndLifetimeAreTheConstructorsParameters) {
  Sessions s(2 * kS, 5 * kS);
  EXPECT_EQ(s.idle_ns(), 2 * kS);
  EXPECT_EQ(s.lifetime_ns(), 5 * kS);
  const std::string a = s.issue(kAlice, kT0);
  EXPECT_TRUE(s.check(a, kT0 + kS));
  EXPECT_FALSE(s.check(a, kT0 + 3 * kS + 1));
  const std::string b = s.issue(kAlice, kT0);
  for (std::int64_t t = kT0 + kS; t < kT0 + 5 * kS; t += kS) EXPECT_TRUE(s.check(b, t));
  EXPECT_FALSE(s.check(b, kT0 + 5 * kS));
  Sessions defaults;
  EXPECT_EQ(defaults.idle_ns(), 30 * kMin);
  EXPECT_EQ(defaults.lifetime_ns(), 8 * 60 * kMin);
}

TEST(Sessions, RevokeEndsOneSessionAndRevokeUserEveryOneOfThatUser) {
  Sessions s;
  const std::string a1 = s.issue(kAlice, kT0), a2 = s.issue(kAlice, kT0), b = s.issue(kBob, kT0);
  s.revoke(a1);
  EXPECT_FALSE(s.check(a1, kT0));
  EXPECT_TRUE(s.check(a2, kT0));
  s.revoke(a1);  // twice: nothing
  s.revoke("not a token");
  EXPECT_EQ(s.size(), 2u);
  s.revoke_user("alice");
  EXPECT_FALSE(s.check(a2, kT0));
  EXPECT_TRUE(s.check(b, kT0)) << "bob's session stays";
  s.revoke_user("nobody");
  EXPECT_EQ(s.size(), 1u);
}

TEST(Sessions, AtMost1024SessionsTheOldestGoesFirst) {
  Sessions s;
  std::vector<std::string> tokens;
  for (std::size_t i = 0; i < kMaxSessions; ++i) tokens.push_back(s.issue(kAlice, kT0 + static_cast<std::int64_t>(i)));
  EXPECT_EQ(s.size(), 1024u);
  const std::string newest = s.issue(kBob, kT0 + 2000);
  EXPECT_EQ(s.size(), 1024u);
  EXPECT_FALSE(s.check(tokens[0], kT0 + 3000)) << "the oldest login went";
  EXPECT_TRUE(s.check(tokens[1], kT0 + 3000));
  EXPECT_TRUE(s.check(tokens.back(), kT0 + 3000));
  EXPECT_TRUE(s.check(newest, kT0 + 3000));
  s.issue(kBob, kT0 + 4000);
  EXPECT_FALSE(s.check(tokens[1], kT0 + 5000)) << "then the next oldest, used or not";
}

TEST(Sessions, ExpiredSessionsMakeRoomBeforeLiveOnesAreEnded) {
  Sessions s(kMin, 60 * kMin, 3);
  const std::string old1 = s.issue(kAlice, kT0);
  const std::string old2 = s.issue(kAlice, kT0);
  const std::string live = s.issue(kBob, kT0 + 30 * kS);
  ASSERT_TRUE(s.check(live, kT0 + 80 * kS));
  s.issue(kBob, kT0 + 80 * kS);  // old1 and old2 are idle for more than a minute by now
  EXPECT_EQ(s.size(), 2u);
  EXPECT_TRUE(s.check(live, kT0 + 81 * kS)) << "not the oldest live one";
}

TEST(Sessions, ThreadsIssueCheckAndRevokeAtOnce) {
  Sessions s(kMin, 60 * kMin, 64);
  std::atomic<int> checked{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      const User u{"user" + std::to_string(t), Role::Viewer, 0};
      for (int i = 0; i < 500; ++i) {
        const std::string token = s.issue(u, kT0 + i);
        if (s.check(token, kT0 + i)) ++checked;
        if (i % 3 == 0) s.revoke(token);
        if (i % 100 == 99) s.revoke_user(u.name);
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_GT(checked.load(), 0);
  EXPECT_LE(s.size(), 64u);
}

// ------------------------------------------------------------ LoginLimiter

TEST(LoginLimiter, TheDelayIsNoneForThreeFailuresThenOneSecondDoublingUpToAMinute) {
  EXPECT_EQ(login_delay_ns(0), 0);
  EXPECT_EQ(login_delay_ns(2), 0);
  EXPECT_EQ(login_delay_ns(3), 1 * kS);
  EXPECT_EQ(login_delay_ns(4), 2 * kS);
  EXPECT_EQ(login_delay_ns(5), 4 * kS);
  EXPECT_EQ(login_delay_ns(8), 32 * kS);
  EXPECT_EQ(login_delay_ns(9), 60 * kS);
  EXPECT_EQ(login_delay_ns(1'000'000), 60 * kS) << "never more than a minute: a delay, not a lockout";
}

TEST(LoginLimiter, FailuresFromOneAddressSlowItDownWithAGrowingDelayFromItsLastFailure) {
  LoginLimiter l;
  for (int i = 0; i < 3; ++i) {
    EXPECT_FALSE(l.refused_for_ns("192.0.2.7", "user" + std::to_string(i), kT0 + i)) << i;
    l.failed("192.0.2.7", "user" + std::to_string(i), kT0 + i);
  }
  EXPECT_EQ(l.refused_for_ns("192.0.2.7", "someone", kT0 + 2), 1 * kS) << "after three, a second from the last";
  EXPECT_FALSE(l.refused_for_ns("192.0.2.7", "someone", kT0 + 2 + kS));
  EXPECT_FALSE(l.refused_for_ns("192.0.2.8", "someone", kT0 + 3)) << "another address";
  std::int64_t t = kT0 + 2 + kS, previous = kS;
  for (int i = 0; i < 4; ++i) {
    l.failed("192.0.2.7", "someone", t);
    const auto wait = l.refused_for_ns("192.0.2.7", "someone", t);
    ASSERT_TRUE(wait);
    EXPECT_EQ(*wait, 2 * previous) << "each failure doubles the wait: failure " << 4 + i;
    previous = *wait;
    t += *wait;
    EXPECT_FALSE(l.refused_for_ns("192.0.2.7", "someone", t)) << "and the wait ends";
  }
}

TEST(LoginLimiter, FailuresForOneNameNeverKeepTheRightPasswordFromAnotherAddressOut) {
  // The issue's case: wrong passwords for eng from one address lock eng out
  // everywhere. Here they slow down the attacker's address and the name,
  // and the engineer at another station logs in at once.
  LoginLimiter l;
  std::int64_t t = kT0;
  for (int i = 0; i < 50; ++i) {
    if (auto wait = l.refused_for_ns("192.0.2.66", "eng", t)) t += *wait;
    l.failed("192.0.2.66", "eng", t);
  }
  EXPECT_EQ(l.refused_for_ns("192.0.2.66", "eng", t), kLoginMaxDelayNs) << "the attacker waits the longest delay";
  EXPECT_FALSE(l.refused_for_ns("198.51.100.1", "eng", t)) << "the engineer at another address is not held back";
  // Failures spread over many addresses: each address, once it has failed
  // for the name, serves the name's delay from its own last failure.
  for (int i = 0; i < 20; ++i) l.failed("203.0.113." + std::to_string(i), "eng", t);
  EXPECT_EQ(l.refused_for_ns("203.0.113.5", "eng", t), kLoginMaxDelayNs) << "a guesser's second try for the name waits";
  EXPECT_FALSE(l.refused_for_ns("203.0.113.5", "bob", t)) << "one failure of the address: another name is not delayed";
  // An engineer who mistypes waits at most the longest delay from their own
  // failure, however often the attacker tries meanwhile.
  l.failed("198.51.100.1", "eng", t);
  for (int i = 1; i <= 59; ++i) l.failed("192.0.2.66", "eng", t + i * kS);
  EXPECT_EQ(l.refused_for_ns("198.51.100.1", "eng", t + 30 * kS), 30 * kS);
  EXPECT_FALSE(l.refused_for_ns("198.51.100.1", "eng", t + kLoginMaxDelayNs));
}

TEST(LoginLimiter, QuietForFifteenMinutesAKeyStartsAfresh) {
  LoginLimiter l;
  for (int i = 0; i < 6; ++i) l.failed("192.0.2.7", "alice", kT0 + i);
  EXPECT_TRUE(l.refused_for_ns("192.0.2.7", "alice", kT0 + 10));
  EXPECT_FALSE(l.refused_for_ns("192.0.2.7", "alice", kT0 + 5 + kLoginForgetNs));
  EXPECT_EQ(l.tracked(), 1u) << "the name's record is looked at only with a pair's: forgotten when next seen";
  l.failed("192.0.2.7", "alice", kT0 + 5 + kLoginForgetNs);
  EXPECT_FALSE(l.refused_for_ns("192.0.2.7", "alice", kT0 + 6 + kLoginForgetNs)) << "one failure, not seven";
}

TEST(LoginLimiter, ASuccessForgetsTheAddresssFailuresNotTheNames) {
  LoginLimiter l;
  for (int i = 0; i < 5; ++i) l.failed("192.0.2.7", "alice", kT0 + i);
  l.succeeded("192.0.2.7", "alice");
  EXPECT_EQ(l.tracked(), 1u) << "the name's count stays";
  EXPECT_FALSE(l.refused_for_ns("192.0.2.7", "alice", kT0 + 5));
  l.failed("192.0.2.7", "alice", kT0 + 10);
  EXPECT_EQ(l.refused_for_ns("192.0.2.7", "alice", kT0 + 10), 8 * kS)
      << "a new failure of the address for the name: the name's six failures set the delay";
  EXPECT_FALSE(l.refused_for_ns("192.0.2.7", "bob", kT0 + 10)) << "the address itself has one failure";
}

TEST(LoginLimiter, AnIPv6HostCountsAsItsSlash64AndAMappedIPv4AsTheIPv4Address) {
  LoginLimiter l;
  for (int i = 0; i < 5; ++i) l.failed("2001:db8:1:2::" + std::to_string(i + 1), "u" + std::to_string(i), kT0);
  EXPECT_TRUE(l.refused_for_ns("2001:db8:1:2:ffff::9", "other", kT0 + kS));
  EXPECT_FALSE(l.refused_for_ns("2001:db8:1:3::1", "other", kT0 + kS)) << "another /64";
  for (int i = 0; i < 5; ++i) l.failed("::ffff:192.0.2.9", "v" + std::to_string(i), kT0);
  EXPECT_TRUE(l.refused_for_ns("192.0.2.9", "other", kT0 + kS));
}

TEST(LoginLimiter, MemoryIsBoundedTheKeyFailedLongestAgoGoes) {
  LoginLimiter l;
  for (int i = 0; i < 5; ++i) l.failed("192.0.2.7", "alice", kT0 + i);
  for (int i = 0; i < 10'000; ++i) {
    l.failed("10." + std::to_string(i / 65536) + "." + std::to_string(i / 256 % 256) + "." + std::to_string(i % 256),
             "name" + std::to_string(i), kT0 + 10 + i);
    ASSERT_LE(l.tracked(), kLoginTrackedKeys);
  }
  EXPECT_EQ(l.tracked(), kLoginTrackedKeys);
  l.failed("192.0.2.7", "alice", kT0 + 20'000);
  EXPECT_FALSE(l.refused_for_ns("192.0.2.7", "alice", kT0 + 20'001)) << "its first five failures were evicted";
  for (int i = 0; i < 4; ++i) l.failed("192.0.2.7", "alice", kT0 + 20'002 + i);
  EXPECT_TRUE(l.refused_for_ns("192.0.2.7", "alice", kT0 + 20'010)) << "a key that keeps failing stays";

  LoginLimiter huge;
  huge.failed(std::string(1 << 20, 'a'), std::string(1 << 20, 'u'), kT0);
  for (int i = 0; i < 4; ++i) huge.failed(std::string(1 << 20, 'a'), std::string(1 << 20, 'v'), kT0);
  EXPECT_TRUE(huge.refused_for_ns(std::string(1 << 20, 'a'), "x", kT0)) << "a long key is cut, not refused";
}

TEST(LoginLimiter, ThreadsFailAndAskAtOnce) {
  LoginLimiter l(256);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < 2000; ++i) {
        const std::string address = "192.0.2." + std::to_string(t), user = "u" + std::to_string(i % 300);
        if (!l.refused_for_ns(address, user, kT0 + i)) l.failed(address, user, kT0 + i);
        if (i % 50 == 0) l.succeeded(address, user);
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_LE(l.tracked(), 256u);
}

// ---------------------------------------------------------------- HashGate

TEST(SessionsHashGate, LetsTwoHashesThroughAtOnceAndTheThirdIsBusy) {
  HashGate gate;
  auto a = gate.try_acquire();
  auto b = gate.try_acquire();
  EXPECT_TRUE(a);
  EXPECT_TRUE(b);
  {
    auto c = gate.try_acquire();
    EXPECT_FALSE(c) << "busy: the server answers 503";
  }
  a.release();
  EXPECT_FALSE(a);
  auto c = gate.try_acquire();
  EXPECT_TRUE(c);
  HashGate::Permit moved = std::move(b);
  EXPECT_FALSE(b);
  EXPECT_TRUE(moved);
  EXPECT_FALSE(gate.try_acquire());
  moved = HashGate::Permit();  // released by the assignment
  EXPECT_TRUE(gate.try_acquire());
}

TEST(SessionsHashGate, ThreadsNeverHoldMoreThanTwoPermits) {
  HashGate gate;
  std::atomic<int> inside{0}, most{0}, busy{0}, through{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t)
    threads.emplace_back([&] {
      for (int i = 0; i < 2000; ++i) {
        auto permit = gate.try_acquire();
        if (!permit) {
          ++busy;
          continue;
        }
        const int now = ++inside;
        for (int seen = most.load(); now > seen && !most.compare_exchange_weak(seen, now);) {
        }
        std::this_thread::yield();
        --inside;
        ++through;
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_LE(most.load(), kConcurrentHashes);
  EXPECT_GT(through.load(), 0);
  EXPECT_EQ(busy.load() + through.load(), 8 * 2000);
}

}  // namespace
}  // namespace syncplc::web
