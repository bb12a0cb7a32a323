#include "runtime/web/login_events.hpp"

#include <algorithm>

namespace syncplc::web {

LoginEvents::LoginEvents(std::int64_t window_ns, std::size_t max_keys)
    : window_ns_(window_ns), max_keys_(std::max<std::size_t>(max_keys, 1)) {}

bool LoginEvents::record_login(const std::string& user, const std::string& role, const std::string& host,
                               std::int64_t now_ns) {
  const std::string key = user + '\n' + role + '\n' + host;
  std::lock_guard lock(mutex_);
  if (const auto it = recorded_.find(key); it != recorded_.end()) {
    if (now_ns - it->second < window_ns_) return false;
    it->second = now_ns;
    return true;
  }
  if (recorded_.size() >= max_keys_) {
    // Those past their window first; else the oldest. Either way the next
    // login of the one dropped is recorded: more events, never fewer.
    for (auto it = recorded_.begin(); it != recorded_.end();)
      it = now_ns - it->second >= window_ns_ ? recorded_.erase(it) : std::next(it);
    if (recorded_.size() >= max_keys_)
      recorded_.erase(std::min_element(recorded_.begin(), recorded_.end(),
                                       [](const auto& a, const auto& b) { return a.second < b.second; }));
  }
  recorded_.emplace(key, now_ns);
  return true;
}

std::string failed_login_text(const std::string& name, bool user_exists) {
  return "login as " + (user_exists ? "'" + name + "'" : std::string("an unknown user name")) +
         " refused: wrong user name or password";
}

}  // namespace syncplc::web
