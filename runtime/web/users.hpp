// The users of the HTTP API and the HMI (docs/http-api.md, "Authentication
// and roles"; docs/store.md, "Users"): one row each in the table `users` of
// the PLC's database, with a role and an Argon2id hash of the password,
// never the password. There is no default user: the first one is made with
// `syncplc user add`.
//
// A UserStore has its own read-write connection, without the instance lock,
// so `syncplc user` works beside a running `syncplc run` whose store thread
// writes the same file: a write waits up to kUsersBusyTimeoutMs for the
// store thread's transaction to end.
//
// Thread-safe: one mutex guards the connection; it is never held while a
// password is hashed, so one slow hash does not hold up another's lookup
// (the server bounds the hashes themselves with a HashGate, sessions.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/store/schema.hpp"
#include "runtime/web/roles.hpp"

namespace SQLite {
class Database;
}

namespace syncplc::web {

// How long a write waits for another connection's transaction (the store
// thread's commits take milliseconds; 5 s is far beyond any of them).
inline constexpr int kUsersBusyTimeoutMs = 5000;
inline constexpr std::size_t kUserNameMaxBytes = 64;
inline constexpr std::size_t kPasswordMinBytes = 8;
// Argon2 reads the whole password; a bound keeps a login's cost known.
inline constexpr std::size_t kPasswordMaxBytes = 1024;

struct User {
  std::string name;
  Role role = Role::Viewer;
  std::int64_t created_ns = 0;  // wall time, ns since 1970 (UTC)
  // The credential stamp: random, new at add, at every password or role
  // change. A session holds the stamp of its login and ends when the row's
  // differs (or the row is gone): a removed user added again with the same
  // name gets a new stamp, so no token of the old one is theirs.
  std::int64_t stamp = 0;
};

// "" when `name` may name a user (1 to 64 of A-Z a-z 0-9 _ . @ -), else why not.
std::string check_user_name(std::string_view name);
// "" when `password` may be a password (8 to 1024 bytes), else why not.
std::string check_password(std::string_view password);

class UserStore {
 public:
  // Opens (creating file and directory when missing, mode 0600 and 0700 as
  // the PLC's store does) the database at `db_path` and brings the table
  // `users` up to date. Null with `error` when it cannot.
  static std::unique_ptr<UserStore> open(const std::string& db_path, std::string* error);
  ~UserStore();
  UserStore(const UserStore&) = delete;
  UserStore& operator=(const UserStore&) = delete;

  // Each false with `error` saying why: a name or password that is not
  // valid, a name that exists (add) or does not (the others), a database
  // that refuses the write. add, set_password and set_role give the user a
  // new stamp: every session of theirs ends at its next request.
  bool add(const std::string& name, const std::string& password, Role role, std::string* error);
  bool remove(const std::string& name, std::string* error);
  bool set_password(const std::string& name, const std::string& password, std::string* error);
  bool set_role(const std::string& name, Role role, std::string* error);

  // Every user whose role can be read, by name. A row whose role or hash is
  // damaged is told to the log (a damaged role leaves the row out). Throws
  // std::runtime_error when the database cannot be read.
  std::vector<User> list();
  // The user `name`, if there is one with a role that can be read (for a
  // server confirming a session's user between logins). Throws as list().
  std::optional<User> find(const std::string& name);
  // Whether `name` has a row, damaged or not. Throws as list().
  bool exists(const std::string& name);
  // Rows in the table, damaged or not. Throws as list().
  std::size_t count();

  // The user if `password` is theirs. Always costs one Argon2id hash, also
  // for a name that is not there (a fixed dummy hash), so the time taken
  // does not tell which names exist. A damaged row, a database that cannot
  // be read: nullopt, and the log says why. Never throws.
  std::optional<User> verify(const std::string& name, const std::string& password);

  // Where problems go (damaged rows, a failed read in verify); by default
  // stderr as "syncplc: users: ...". Called from the caller's thread; set it
  // before the store is shared.
  void set_log(std::function<void(const std::string&)> log);

  const std::string& path() const { return path_; }
  static const store::SchemaPart& schema();

 private:
  UserStore() = default;
  void log(const std::string& message) const;
  std::string path_;
  std::mutex mutex_;  // guards db_
  std::unique_ptr<SQLite::Database> db_;
  std::function<void(const std::string&)> log_;
};

// The Argon2id hash a new password gets (libsodium's crypto_pwhash_str with
// the parameters below), "" when the memory for it cannot be had.
std::string hash_password(std::string_view password);
// The hash verify() spends for a name that has no (usable) row: made with
// the same parameters as hash_password, of a password nobody knows.
std::string_view dummy_password_hash();

}  // namespace syncplc::web
