#include "runtime/web/sessions.hpp"

#include <arpa/inet.h>
#include <sodium.h>

#include <algorithm>
#include <cstring>

#include "runtime/web/sodium_ready.hpp"

namespace syncplc::web {

static_assert(sodium_base64_ENCODED_LEN(kTokenBytes, sodium_base64_VARIANT_URLSAFE_NO_PADDING) == kTokenChars + 1);

// --- Sessions --------------------------------------------------------------

Sessions::Sessions(std::int64_t idle_ns, std::int64_t lifetime_ns, std::size_t max_sessions)
    : idle_ns_(idle_ns), lifetime_ns_(lifetime_ns), max_sessions_(std::max<std::size_t>(max_sessions, 1)) {
  sodium_ready();
  // Keyed, with a key that never leaves the process: a hash seen in memory
  // cannot be matched against guessed tokens elsewhere.
  static_assert(std::tuple_size_v<decltype(key_)> == crypto_generichash_KEYBYTES);
  randombytes_buf(key_.data(), key_.size());
  entries_.reserve(max_sessions_);
}

Sessions::Digest Sessions::digest(const std::string& token) const {
  Digest d;
  crypto_generichash(d.data(), d.size(), reinterpret_cast<const unsigned char*>(token.data()), token.size(),
                     key_.data(), key_.size());
  return d;
}

std::size_t Sessions::find(const Digest& d) const {
  // Every entry compared, in constant time each, whatever matches: how long
  // a check takes says nothing about the table.
  std::size_t found = entries_.size();
  for (std::size_t i = 0; i < entries_.size(); ++i)
    if (sodium_memcmp(entries_[i].digest.data(), d.data(), d.size()) == 0) found = i;
  return found;
}

void Sessions::forget(std::size_t i) {
  entries_[i] = std::move(entries_.back());
  entries_.pop_back();
}

std::string Sessions::issue(const User& user, std::int64_t now_ns) {
  unsigned char raw[kTokenBytes];
  randombytes_buf(raw, sizeof raw);
  char text[kTokenChars + 1];
  sodium_bin2base64(text, sizeof text, raw, sizeof raw, sodium_base64_VARIANT_URLSAFE_NO_PADDING);
  sodium_memzero(raw, sizeof raw);
  std::string token(text, kTokenChars);
  sodium_memzero(text, sizeof text);

  Entry e{digest(token), Session{user.name, user.role, user.stamp, now_ns, now_ns}};
  std::lock_guard lock(mutex_);
  for (std::size_t i = entries_.size(); i-- > 0;) {
    const Session& s = entries_[i].session;
    if (now_ns - s.last_ns >= idle_ns_ || now_ns - s.issued_ns >= lifetime_ns_) forget(i);
  }
  if (entries_.size() >= max_sessions_) {
    const auto oldest = std::min_element(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) {
      return a.session.issued_ns < b.session.issued_ns;
    });
    forget(static_cast<std::size_t>(oldest - entries_.begin()));
  }
  entries_.push_back(std::move(e));
  return token;
}

std::optional<Session> Sessions::check(const std::string& token, std::int64_t now_ns) {
  if (token.size() != kTokenChars) return std::nullopt;  // never issued: no need to look
  const Digest d = digest(token);
  std::lock_guard lock(mutex_);
  const std::size_t i = find(d);
  if (i == entries_.size()) return std::nullopt;
  Session& s = entries_[i].session;
  if (now_ns - s.last_ns >= idle_ns_ || now_ns - s.issued_ns >= lifetime_ns_) {
    forget(i);
    return std::nullopt;
  }
  s.last_ns = std::max(s.last_ns, now_ns);
  return s;
}

void Sessions::revoke(const std::string& token) {
  if (token.size() != kTokenChars) return;
  const Digest d = digest(token);
  std::lock_guard lock(mutex_);
  if (const std::size_t i = find(d); i < entries_.size()) forget(i);
}

void Sessions::revoke_user(const std::string& name) {
  std::lock_guard lock(mutex_);
  for (std::size_t i = entries_.size(); i-- > 0;)
    if (entries_[i].session.user == name) forget(i);
}

std::size_t Sessions::size() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

// --- LoginLimiter ----------------------------------------------------------

namespace {

// A key's bytes kept at most: user names come from the request body, and
// the table's memory is bounded by keys times this (a valid name has 64).
constexpr std::size_t kKeyMaxBytes = 256;

// One key per host: an IPv6 host usually holds a whole /64 and could
// otherwise take a fresh address for every five attempts; an IPv4 address
// written as IPv6 (::ffff:192.0.2.1) counts as the IPv4 address.
std::string address_key(const std::string& address) {
  in6_addr a6{};
  if (inet_pton(AF_INET6, address.c_str(), &a6) == 1) {
    char text[INET6_ADDRSTRLEN];
    if (IN6_IS_ADDR_V4MAPPED(&a6)) {
      if (inet_ntop(AF_INET, &a6.s6_addr[12], text, sizeof text)) return std::string("a ") + text;
    } else {
      std::memset(&a6.s6_addr[8], 0, 8);
      if (inet_ntop(AF_INET6, &a6, text, sizeof text)) return std::string("a ") + text + "/64";
    }
  }
  return "a " + address.substr(0, kKeyMaxBytes);
}

std::string user_key(const std::string& user) { return "u " + user.substr(0, kKeyMaxBytes); }

// The address's failures for one name: where the name's delay is served from.
std::string pair_key(const std::string& address, const std::string& user) {
  return "p " + address_key(address).substr(2) + " " + user.substr(0, kKeyMaxBytes);
}

}  // namespace

std::int64_t login_delay_ns(std::int64_t failures) {
  if (failures < kLoginFreeFailures) return 0;
  std::int64_t d = kLoginFirstDelayNs;
  for (std::int64_t i = kLoginFreeFailures; i < failures && d < kLoginMaxDelayNs; ++i) d *= 2;
  return std::min(d, kLoginMaxDelayNs);
}

LoginLimiter::LoginLimiter(std::size_t max_keys) : max_keys_(std::max<std::size_t>(max_keys, 3)) {}

const LoginLimiter::Failures* LoginLimiter::look(const std::string& key, std::int64_t now_ns) {
  const auto it = failures_.find(key);
  if (it == failures_.end()) return nullptr;
  if (now_ns - it->second.last_ns >= kLoginForgetNs) {  // quiet long enough: a fresh start
    forget(key);
    return nullptr;
  }
  return &it->second;
}

void LoginLimiter::forget(const std::string& key) {
  if (const auto it = failures_.find(key); it != failures_.end()) {
    recency_.erase(it->second.recency);
    failures_.erase(it);
  }
}

void LoginLimiter::record(const std::string& key, std::int64_t now_ns) {
  (void)look(key, now_ns);  // an old record starts afresh
  auto it = failures_.find(key);
  if (it == failures_.end()) {
    if (failures_.size() >= max_keys_) {  // the key whose latest failure is oldest goes
      failures_.erase(recency_.back());
      recency_.pop_back();
    }
    recency_.push_front(key);
    it = failures_.emplace(key, Failures{}).first;
    it->second.recency = recency_.begin();
  } else {
    recency_.splice(recency_.begin(), recency_, it->second.recency);
  }
  ++it->second.count;
  it->second.last_ns = std::max(it->second.last_ns, now_ns);
}

std::optional<std::int64_t> LoginLimiter::refused_for_ns(const std::string& address, const std::string& user,
                                                          std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  std::int64_t until = now_ns;
  // The address: its own failures, whatever names they were for.
  if (const Failures* a = look(address_key(address), now_ns)) until = std::max(until, a->last_ns + login_delay_ns(a->count));
  // The name: the delay all addresses' failures for it give, served from
  // this address's own last failure for it. An address that never failed
  // for the name is not held back: the right password from another station
  // gets in whatever is tried elsewhere.
  if (const Failures* pair = look(pair_key(address, user), now_ns)) {
    const Failures* name = look(user_key(user), now_ns);
    const std::int64_t count = std::max(pair->count, name ? name->count : 0);
    until = std::max(until, pair->last_ns + login_delay_ns(count));
  }
  if (until <= now_ns) return std::nullopt;
  return until - now_ns;
}

void LoginLimiter::failed(const std::string& address, const std::string& user, std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  record(address_key(address), now_ns);
  record(user_key(user), now_ns);
  record(pair_key(address, user), now_ns);
}

void LoginLimiter::succeeded(const std::string& address, const std::string& user) {
  std::lock_guard lock(mutex_);
  forget(address_key(address));
  forget(pair_key(address, user));
}

std::size_t LoginLimiter::tracked() const {
  std::lock_guard lock(mutex_);
  return failures_.size();
}

// --- HashGate --------------------------------------------------------------

HashGate::Permit& HashGate::Permit::operator=(Permit&& o) noexcept {
  if (this != &o) {
    release();
    gate_ = o.gate_;
    o.gate_ = nullptr;
  }
  return *this;
}

void HashGate::Permit::release() {
  if (gate_) gate_->free_.release();
  gate_ = nullptr;
}

HashGate::Permit HashGate::try_acquire() { return free_.try_acquire() ? Permit(this) : Permit(); }

}  // namespace syncplc::web
