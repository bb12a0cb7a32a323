// What a login leaves in the event log (docs/http-api.md, "Failed logins"
// and "Events"). The log is for what changed the machine: a command-line
// call with --user logs in each time, and recorded every time those logins
// buried the writes and reloads (half of the events in a few minutes). So a
// successful login is recorded once per user, role and client host within
// kLoginEventWindowNs; the logins between are only counted
// (ServerCounters::logins). A failed login names the user only when one of that name
// exists: a password typed into the name field never reaches the log, which
// anonymous readers may read.
//
// Thread-safe behind one mutex; times are ns of the monotonic clock, passed
// in so that tests choose them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <unordered_map>

namespace syncplc::web {

inline constexpr std::int64_t kLoginEventWindowNs = 15LL * 60 * 1'000'000'000;  // 15 min
inline constexpr std::size_t kLoginEventKeys = 1024;  // users x hosts remembered

class LoginEvents {
 public:
  explicit LoginEvents(std::int64_t window_ns = kLoginEventWindowNs, std::size_t max_keys = kLoginEventKeys);
  // Whether this login of `user` (with `role`) from `host` (the address,
  // without the port: each CLI call comes from a new one) is to be
  // recorded: the first one, or the first after `window_ns` without a
  // recorded one for the same user, role and host.
  bool record_login(const std::string& user, const std::string& role, const std::string& host, std::int64_t now_ns);

 private:
  const std::int64_t window_ns_;
  const std::size_t max_keys_;
  std::mutex mutex_;
  std::unordered_map<std::string, std::int64_t> recorded_;  // key -> when its login was last recorded
};

// The event text of a failed login as `name`: the name only when
// `user_exists` (it names a user of this PLC), else "an unknown user name".
std::string failed_login_text(const std::string& name, bool user_exists);

}  // namespace syncplc::web
