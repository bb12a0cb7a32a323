// Live-value subscriptions (docs/http-api.md, "Subscriptions"): a client
// creates one, adds and drops references as its views open and close, and
// reads its values from one stream; no list travels in a URL, so any number
// of references fits. A subscription belongs to the session that created it
// (or to anonymous readers, where they may read), is named by a random id,
// and ends when it is deleted, when its session ends, or after a minute
// without a stream. Memory is bounded: so many subscriptions, so many
// references in each and in all, each reference so long.
//
// Plain data under one mutex, on HTTP threads only (never a scan's).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace syncplc::web {

struct SubscriptionLimits {
  std::size_t max_subscriptions = 128;
  std::size_t max_refs = 4096;           // in one subscription
  std::size_t max_total_refs = 32768;    // in all of them
  std::size_t max_ref_bytes = 256;
  std::int64_t idle_ns = 60'000'000'000;  // without a stream this long: removed
};

// A subscription as a stream or a request sees it (a copy).
struct SubscriptionView {
  std::string id;
  std::vector<std::string> refs;  // in the order they were added
  std::uint64_t version = 0;      // changes with every add or drop
  double rate = 10;               // updates per second
};

class Subscriptions {
 public:
  explicit Subscriptions(SubscriptionLimits limits = {}) : limits_(limits) {}

  // What add/drop did, for the answer.
  struct Change {
    bool ok = false;
    int status = 200;        // when !ok: 400 (a bad ref), 404 (no such subscription), 409, 503 (a limit)
    std::string error;
    std::vector<std::string> added, dropped;  // refs new to / gone from the subscription
  };

  // A new subscription of `owner` (a session token, "" for anonymous) with
  // `refs`; nullopt with *error / *status (503: the limit) otherwise.
  std::optional<SubscriptionView> create(const std::string& owner, double rate, const std::vector<std::string>& refs,
                                         std::int64_t now_ns, std::string* error, int* status);
  // Adds and drops references; all or nothing.
  Change change(const std::string& id, const std::string& owner, const std::vector<std::string>& add,
                const std::vector<std::string>& drop, std::int64_t now_ns);
  bool remove(const std::string& id, const std::string& owner);
  // The subscription, when `owner` may use it.
  std::optional<SubscriptionView> get(const std::string& id, const std::string& owner) const;
  // Removes every subscription of a session (logout).
  void remove_owner(const std::string& owner);

  // A stream attaches: the newest attach wins (an earlier stream of the same
  // subscription sees attached() false and ends). Returns its attach number, 0 when
  // there is no such subscription for `owner`.
  std::uint64_t attach(const std::string& id, const std::string& owner, std::int64_t now_ns);
  // The stream's tick: its refs when they changed since `version` (*changed),
  // false when the subscription is gone or another stream took it.
  bool poll(const std::string& id, std::uint64_t attach, std::uint64_t* version, std::vector<std::string>* refs,
            bool* changed, std::int64_t now_ns);
  void detach(const std::string& id, std::uint64_t attach, std::int64_t now_ns);

  std::size_t size() const;
  std::size_t total_refs() const;
  const SubscriptionLimits& limits() const { return limits_; }

 private:
  struct Entry {
    std::string owner;
    std::vector<std::string> refs;
    std::uint64_t version = 1;
    double rate = 10;
    std::uint64_t attached = 0;  // the stream that holds it, 0: none
    std::int64_t idle_since_ns = 0;
  };
  void expire(std::int64_t now_ns);  // under mutex_
  Entry* find(const std::string& id, const std::string& owner);
  const Entry* find(const std::string& id, const std::string& owner) const;
  std::string check_ref(const std::string& ref) const;

  SubscriptionLimits limits_;
  mutable std::mutex mutex_;
  std::map<std::string, Entry> entries_;
  std::size_t total_refs_ = 0;
  std::uint64_t next_attach_ = 1;
};

}  // namespace syncplc::web
