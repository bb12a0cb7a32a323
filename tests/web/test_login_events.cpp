// What a login leaves in the event log (runtime/web/login_events.hpp).
#include <gtest/gtest.h>

#include "runtime/web/login_events.hpp"

namespace syncplc::web {
namespace login_events_test {

constexpr std::int64_t kS = 1'000'000'000;
constexpr std::int64_t kT0 = 1'000 * kS;

TEST(LoginEvents, OncePerUserRoleAndHostWithinTheWindow) {
  // The case: a command-line call per login, half the log logins.
  LoginEvents e;
  EXPECT_TRUE(e.record_login("olga", "operator", "127.0.0.1", kT0));
  for (int i = 1; i < 30; ++i) EXPECT_FALSE(e.record_login("olga", "operator", "127.0.0.1", kT0 + i * 10 * kS)) << i;
  EXPECT_TRUE(e.record_login("olga", "operator", "192.0.2.5", kT0 + kS)) << "another host";
  EXPECT_TRUE(e.record_login("erik", "engineer", "127.0.0.1", kT0 + kS)) << "another user";
  EXPECT_TRUE(e.record_login("olga", "engineer", "127.0.0.1", kT0 + 2 * kS)) << "a new role is news";
  EXPECT_TRUE(e.record_login("olga", "operator", "127.0.0.1", kT0 + kLoginEventWindowNs)) << "the window has passed";
  EXPECT_FALSE(e.record_login("olga", "operator", "127.0.0.1", kT0 + kLoginEventWindowNs + kS));
}

TEST(LoginEvents, MemoryIsBoundedAndAForgottenKeyIsRecordedAgain) {
  LoginEvents e(kLoginEventWindowNs, 4);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(e.record_login("u" + std::to_string(i), "viewer", "h", kT0 + i));
  EXPECT_TRUE(e.record_login("u9", "viewer", "h", kT0 + 10)) << "the oldest (u0) made room";
  EXPECT_TRUE(e.record_login("u0", "viewer", "h", kT0 + 11)) << "forgotten: recorded again, never lost";
  EXPECT_FALSE(e.record_login("u3", "viewer", "h", kT0 + 12));
}

TEST(LoginEvents, AFailedLoginNamesOnlyAUser) {
  EXPECT_EQ(failed_login_text("olga", true), "login as 'olga' refused: wrong user name or password");
  EXPECT_EQ(failed_login_text("hunter2-Secret", false),
            "login as an unknown user name refused: wrong user name or password");
}

}  // namespace login_events_test
}  // namespace syncplc::web
