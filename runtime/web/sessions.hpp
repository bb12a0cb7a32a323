// What a login leaves behind in `syncplc run` (docs/http-api.md,
// "Authentication and roles"), all of it in memory only: a restart ends
// every session and forgets every failed attempt.
//
//   - Sessions: the bearer tokens handed out by POST /api/v1/login. A token
//     is 32 random bytes, base64url; only a keyed hash of it is kept, so the
//     table (or a core dump of it) gives nobody a token to send. A session
//     ends after kSessionIdleNs without a request, kSessionLifetimeNs after
//     the login, at logout, or when its user's credential stamp (users.hpp)
//     is no longer the one of the login: a password or role change, a
//     removal (also when the name is added again).
//   - LoginLimiter: failures slow down, never lock out (docs/http-api.md,
//     "Failed logins"). After kLoginFreeFailures failures an address waits
//     a delay that doubles with each further failure, up to kLoginMaxDelayNs,
//     before it may try again (429, Retry-After). Failures for a user name
//     from all addresses together set the delay for that name, but each
//     address serves it from its own last failure for the name: an address
//     that has not failed for the name is not held back by it, so an
//     attacker elsewhere cannot keep the right password out.
//   - HashGate: at most kConcurrentHashes password hashes at once. Each
//     Argon2id hash takes 64 MiB (users.cpp): unbounded parallel logins
//     would exhaust the PLC's memory; a login beyond the gate is answered
//     "busy" (503) at once instead of waiting.
//
// Used by the HTTP server's worker threads, never by a scan: each class is
// thread-safe behind its own one mutex (HashGate: a semaphore). Times are
// ns of one monotonic clock (runtime/core/monotonic_clock.hpp), passed in so
// that tests choose them.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <list>
#include <mutex>
#include <optional>
#include <semaphore>
#include <string>
#include <unordered_map>
#include <vector>

#include "runtime/web/roles.hpp"
#include "runtime/web/users.hpp"

namespace syncplc::web {

inline constexpr std::int64_t kSessionIdleNs = 30LL * 60 * 1'000'000'000;      // 30 min without a request
inline constexpr std::int64_t kSessionLifetimeNs = 8LL * 3600 * 1'000'000'000;  // 8 h after the login
inline constexpr std::size_t kMaxSessions = 1024;  // past it, a login ends the oldest session
inline constexpr std::size_t kTokenBytes = 32;     // random bytes in a token
inline constexpr std::size_t kTokenChars = 43;     // its base64url text, without padding

struct Session {
  std::string user;
  Role role = Role::Viewer;
  std::int64_t stamp = 0;      // the user's credential stamp at the login
  std::int64_t issued_ns = 0;  // the login
  std::int64_t last_ns = 0;    // the last request that showed the token
};

class Sessions {
 public:
  explicit Sessions(std::int64_t idle_ns = kSessionIdleNs, std::int64_t lifetime_ns = kSessionLifetimeNs,
                    std::size_t max_sessions = kMaxSessions);

  // A new session for `user`: its token, to hand to the client once.
  std::string issue(const User& user, std::int64_t now_ns);
  // The session of `token`, its last_ns now `now_ns`; nullopt when there is
  // none or it has expired (an expired one is forgotten).
  std::optional<Session> check(const std::string& token, std::int64_t now_ns);
  // Logout: the token's session ends (nothing when there is none).
  void revoke(const std::string& token);
  // Every session of `name` ends: after the user is removed or given
  // another role, so that no one keeps rights they no longer have.
  void revoke_user(const std::string& name);
  // Sessions held, expired ones not yet forgotten included.
  std::size_t size() const;

  std::int64_t idle_ns() const { return idle_ns_; }
  std::int64_t lifetime_ns() const { return lifetime_ns_; }

 private:
  using Digest = std::array<unsigned char, 32>;
  struct Entry {
    Digest digest;
    Session session;
  };
  Digest digest(const std::string& token) const;
  // Index of `d` in entries_, or entries_.size(); under mutex_.
  std::size_t find(const Digest& d) const;
  void forget(std::size_t i);  // under mutex_

  const std::int64_t idle_ns_;
  const std::int64_t lifetime_ns_;
  const std::size_t max_sessions_;
  std::array<unsigned char, 32> key_{};  // the hash's key, random per process
  mutable std::mutex mutex_;
  std::vector<Entry> entries_;  // at most max_sessions_, in no order
};

// Failures a key (an address, a name) has before any delay.
inline constexpr int kLoginFreeFailures = 3;
inline constexpr std::int64_t kLoginFirstDelayNs = 1LL * 1'000'000'000;  // after the free ones; doubles
inline constexpr std::int64_t kLoginMaxDelayNs = 60LL * 1'000'000'000;   // the longest wait
// A key without a failure for this long is forgotten: its count starts afresh.
inline constexpr std::int64_t kLoginForgetNs = 15LL * 60 * 1'000'000'000;
inline constexpr std::size_t kLoginTrackedKeys = 4096;  // addresses, names and pairs together

// The wait after `failures` failures of one key: 0 for the first
// kLoginFreeFailures, then kLoginFirstDelayNs doubling, at most kLoginMaxDelayNs.
std::int64_t login_delay_ns(std::int64_t failures);

class LoginLimiter {
 public:
  explicit LoginLimiter(std::size_t max_keys = kLoginTrackedKeys);

  // nullopt: `address` may try to log in as `user`; else how long (ns, > 0)
  // until it may (the answer's Retry-After, rounded up to seconds).
  std::optional<std::int64_t> refused_for_ns(const std::string& address, const std::string& user, std::int64_t now_ns);
  void failed(const std::string& address, const std::string& user, std::int64_t now_ns);
  // A login that succeeded: the address's failures, and those of the
  // address for this name, are forgotten (the name's own count stays: an
  // attacker's count is not reset by the engineer's login).
  void succeeded(const std::string& address, const std::string& user);
  // Keys (addresses, names, address-and-name pairs) with failures on record
  // (at most max_keys).
  std::size_t tracked() const;

 private:
  struct Failures {
    std::int64_t count = 0;    // since the key was last forgotten
    std::int64_t last_ns = 0;  // the latest failure
    std::list<std::string>::iterator recency;  // its place in recency_
  };
  // The key's record, nullptr when none (or forgotten now); under mutex_.
  const Failures* look(const std::string& key, std::int64_t now_ns);
  void record(const std::string& key, std::int64_t now_ns);  // under mutex_
  void forget(const std::string& key);                        // under mutex_

  const std::size_t max_keys_;
  mutable std::mutex mutex_;
  std::unordered_map<std::string, Failures> failures_;
  std::list<std::string> recency_;  // keys, the latest failure first: the back goes when full
};

inline constexpr int kConcurrentHashes = 2;

// A counting semaphore that is only ever tried, never waited on.
class HashGate {
 public:
  // One of the gate's places while it lives; an empty one (false) when the
  // gate was full.
  class Permit {
   public:
    Permit() = default;
    Permit(Permit&& o) noexcept : gate_(o.gate_) { o.gate_ = nullptr; }
    Permit& operator=(Permit&& o) noexcept;
    ~Permit() { release(); }
    explicit operator bool() const { return gate_ != nullptr; }
    void release();

   private:
    friend class HashGate;
    explicit Permit(HashGate* g) : gate_(g) {}
    HashGate* gate_ = nullptr;
  };

  explicit HashGate(std::ptrdiff_t places = kConcurrentHashes) : free_(places) {}
  // A permit to hash now, or an empty one: the caller answers "busy".
  [[nodiscard]] Permit try_acquire();

 private:
  std::counting_semaphore<> free_;
};

}  // namespace syncplc::web
