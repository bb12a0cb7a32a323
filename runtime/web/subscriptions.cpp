#include "runtime/web/subscriptions.hpp"

#include <sodium.h>

#include <algorithm>
#include <set>

#include "runtime/web/sodium_ready.hpp"

namespace syncplc::web {
namespace {

// The owner is kept as a digest of the session token: the table holds no
// token a memory dump could replay.
std::string owner_digest(const std::string& owner) {
  sodium_ready();
  unsigned char d[crypto_hash_sha256_BYTES];
  crypto_hash_sha256(d, reinterpret_cast<const unsigned char*>(owner.data()), owner.size());
  return std::string(reinterpret_cast<const char*>(d), sizeof d);
}

bool same_owner(const std::string& digest, const std::string& owner) {
  const std::string d = owner_digest(owner);
  return d.size() == digest.size() && sodium_memcmp(d.data(), digest.data(), d.size()) == 0;
}

std::string new_id() {
  sodium_ready();
  unsigned char b[16];
  randombytes_buf(b, sizeof b);
  char hex[2 * sizeof b + 1];
  sodium_bin2hex(hex, sizeof hex, b, sizeof b);
  return hex;
}

}  // namespace

std::string Subscriptions::check_ref(const std::string& ref) const {
  if (ref.empty()) return "an empty reference";
  if (ref.size() > limits_.max_ref_bytes)
    return "a reference longer than " + std::to_string(limits_.max_ref_bytes) + " bytes";
  return {};
}

void Subscriptions::expire(std::int64_t now_ns) {
  for (auto it = entries_.begin(); it != entries_.end();) {
    if (it->second.attached == 0 && now_ns - it->second.idle_since_ns > limits_.idle_ns) {
      total_refs_ -= it->second.refs.size();
      it = entries_.erase(it);
    } else {
      ++it;
    }
  }
}

Subscriptions::Entry* Subscriptions::find(const std::string& id, const std::string& owner) {
  auto it = entries_.find(id);
  if (it == entries_.end() || !same_owner(it->second.owner, owner)) return nullptr;
  return &it->second;
}

const Subscriptions::Entry* Subscriptions::find(const std::string& id, const std::string& owner) const {
  auto it = entries_.find(id);
  if (it == entries_.end() || !same_owner(it->second.owner, owner)) return nullptr;
  return &it->second;
}

std::optional<SubscriptionView> Subscriptions::create(const std::string& owner, double rate,
                                                      const std::vector<std::string>& refs, std::int64_t now_ns,
                                                      std::string* error, int* status) {
  std::vector<std::string> unique;
  std::set<std::string> seen;
  for (const auto& r : refs) {
    if (const std::string why = check_ref(r); !why.empty()) {
      *error = why;
      *status = 400;
      return std::nullopt;
    }
    if (seen.insert(r).second) unique.push_back(r);
  }
  std::lock_guard lock(mutex_);
  expire(now_ns);
  if (entries_.size() >= limits_.max_subscriptions) {
    *error = "this PLC already keeps " + std::to_string(limits_.max_subscriptions) +
             " subscriptions; delete one or try again in a minute";
    *status = 503;
    return std::nullopt;
  }
  if (unique.size() > limits_.max_refs) {
    *error = "at most " + std::to_string(limits_.max_refs) + " references in one subscription";
    *status = 400;
    return std::nullopt;
  }
  if (total_refs_ + unique.size() > limits_.max_total_refs) {
    *error = "this PLC already serves " + std::to_string(total_refs_) + " subscribed references; try again later";
    *status = 503;
    return std::nullopt;
  }
  std::string id = new_id();
  Entry e;
  e.owner = owner_digest(owner);
  e.refs = std::move(unique);
  e.rate = rate;
  e.idle_since_ns = now_ns;
  total_refs_ += e.refs.size();
  SubscriptionView v{id, e.refs, e.version, e.rate};
  entries_.emplace(std::move(id), std::move(e));
  return v;
}

Subscriptions::Change Subscriptions::change(const std::string& id, const std::string& owner,
                                            const std::vector<std::string>& add, const std::vector<std::string>& drop,
                                            std::int64_t now_ns) {
  Change c;
  for (const auto* list : {&add, &drop})
    for (const auto& r : *list)
      if (const std::string why = check_ref(r); !why.empty()) {
        c.status = 400;
        c.error = why;
        return c;
      }
  std::lock_guard lock(mutex_);
  expire(now_ns);
  Entry* e = find(id, owner);
  if (!e) {
    c.status = 404;
    c.error = "no subscription " + id + " (it ends a minute after its last stream, and with its session)";
    return c;
  }
  std::set<std::string> have(e->refs.begin(), e->refs.end());
  const std::set<std::string> gone(drop.begin(), drop.end());
  std::vector<std::string> next;
  for (const auto& r : e->refs) {
    if (gone.count(r)) c.dropped.push_back(r);
    else next.push_back(r);
  }
  for (const auto& r : add) {
    if (gone.count(r) || !have.insert(r).second) continue;  // dropped in the same request, or there already
    next.push_back(r);
    c.added.push_back(r);
  }
  if (next.size() > limits_.max_refs) {
    c.status = 400;
    c.error = "at most " + std::to_string(limits_.max_refs) + " references in one subscription";
    c.added.clear();
    c.dropped.clear();
    return c;
  }
  if (total_refs_ - e->refs.size() + next.size() > limits_.max_total_refs) {
    c.status = 503;
    c.error = "this PLC already serves " + std::to_string(total_refs_) + " subscribed references; try again later";
    c.added.clear();
    c.dropped.clear();
    return c;
  }
  total_refs_ = total_refs_ - e->refs.size() + next.size();
  if (!c.added.empty() || !c.dropped.empty()) ++e->version;
  e->refs = std::move(next);
  if (e->attached == 0) e->idle_since_ns = now_ns;  // in use: not idle
  c.ok = true;
  return c;
}

bool Subscriptions::remove(const std::string& id, const std::string& owner) {
  std::lock_guard lock(mutex_);
  auto it = entries_.find(id);
  if (it == entries_.end() || !same_owner(it->second.owner, owner)) return false;
  total_refs_ -= it->second.refs.size();
  entries_.erase(it);
  return true;
}

void Subscriptions::remove_owner(const std::string& owner) {
  std::lock_guard lock(mutex_);
  for (auto it = entries_.begin(); it != entries_.end();) {
    if (same_owner(it->second.owner, owner)) {
      total_refs_ -= it->second.refs.size();
      it = entries_.erase(it);
    } else {
      ++it;
    }
  }
}

std::optional<SubscriptionView> Subscriptions::get(const std::string& id, const std::string& owner) const {
  std::lock_guard lock(mutex_);
  const Entry* e = find(id, owner);
  if (!e) return std::nullopt;
  return SubscriptionView{id, e->refs, e->version, e->rate};
}

std::uint64_t Subscriptions::attach(const std::string& id, const std::string& owner, std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  expire(now_ns);
  Entry* e = find(id, owner);
  if (!e) return 0;
  e->attached = next_attach_++;
  return e->attached;
}

bool Subscriptions::poll(const std::string& id, std::uint64_t attach, std::uint64_t* version,
                         std::vector<std::string>* refs, bool* changed, std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  auto it = entries_.find(id);
  if (it == entries_.end() || it->second.attached != attach) return false;
  Entry& e = it->second;
  e.idle_since_ns = now_ns;
  *changed = e.version != *version;
  if (*changed) {
    *version = e.version;
    *refs = e.refs;
  }
  return true;
}

void Subscriptions::detach(const std::string& id, std::uint64_t attach, std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  auto it = entries_.find(id);
  if (it == entries_.end() || it->second.attached != attach) return;
  it->second.attached = 0;
  it->second.idle_since_ns = now_ns;
}

std::size_t Subscriptions::size() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

std::size_t Subscriptions::total_refs() const {
  std::lock_guard lock(mutex_);
  return total_refs_;
}

}  // namespace syncplc::web
