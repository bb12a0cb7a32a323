#include "runtime/web/users.hpp"

#include <SQLiteCpp/Database.h>
#include <SQLiteCpp/Statement.h>
#include <sodium.h>
#include <sqlite3.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <stdexcept>

#include "runtime/store/database.hpp"
#include "runtime/store/event_log.hpp"
#include "runtime/web/sodium_ready.hpp"

namespace syncplc::web {
namespace fs = std::filesystem;

namespace {

// Argon2id with libsodium's INTERACTIVE limits: 2 passes over 64 MiB, about
// 0.1 s of one core. The PLC shares its cores and memory with real-time
// tasks: MODERATE (256 MiB, ~0.7 s) or SENSITIVE (1 GiB, seconds) per login
// would take them from the tasks and make each login attempt a lever for a
// denial of service. Online guessing is bounded by the login limiter (a
// delay growing to a minute per address and per name), and 64 MiB per guess with a
// salt per hash still makes guessing from a stolen database file costly.
constexpr unsigned long long kOpsLimit = crypto_pwhash_OPSLIMIT_INTERACTIVE;
constexpr std::size_t kMemLimit = crypto_pwhash_MEMLIMIT_INTERACTIVE;

// crypto_pwhash_str of 32 random bytes that were thrown away, with the
// limits above: nobody knows a password for it. The test suite checks that
// its parameters are still kOpsLimit and kMemLimit, so an unknown name costs
// what a known one does.
constexpr const char* kDummyHash =
    "$argon2id$v=19$m=65536,t=2,p=1$IbFPpClwFeH/y3mvR92vWQ$kDZSDW/ZskpxGauZbFmXgqKhGzocOC2fUHsid6wyF8E";

bool fail(std::string* error, std::string why) {
  if (error) *error = std::move(why);
  return false;
}

bool name_char(unsigned char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '.' ||
         c == '@' || c == '-';
}

std::string quoted_char(unsigned char c) {
  if (c >= 0x21 && c < 0x7f) return std::string("'") + static_cast<char>(c) + "'";
  if (c == ' ') return "a space";
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%02x", c);
  return std::string("the byte ") + hex;
}

// A users row as read; the problems say what cannot be used.
struct Row {
  User user;
  std::string hash;
  std::string role_problem;  // "" when the role was read
  std::string hash_problem;  // "" when the hash can be verified against
};

std::string hash_problem(const SQLite::Column& c, const std::string& hash) {
  if (!c.isText()) return "is not text";
  if (hash.empty()) return "is empty";
  // libsodium reads the hash as a C string of fewer than crypto_pwhash_STRBYTES.
  if (hash.size() >= crypto_pwhash_STRBYTES || hash.find('\0') != std::string::npos) return "is not an Argon2 hash";
  if (crypto_pwhash_str_needs_rehash(hash.c_str(), kOpsLimit, kMemLimit) < 0) return "is not an Argon2 hash";
  return "";
}

// From `SELECT name, role, hash, created_ns, stamp`.
Row read_row(SQLite::Statement& q) {
  Row r;
  r.user.name = q.getColumn(0).getString();
  const SQLite::Column role = q.getColumn(1);
  const auto parsed = role.isText() ? parse_role(role.getString()) : std::nullopt;
  if (parsed) r.user.role = *parsed;
  else r.role_problem = "the role of user '" + r.user.name +
                        "' in the database is damaged (not viewer, operator or engineer); set it with "
                        "`syncplc user role " + r.user.name + " ROLE`";
  const SQLite::Column hash = q.getColumn(2);
  r.hash = hash.getString();
  if (std::string why = hash_problem(hash, r.hash); !why.empty())
    r.hash_problem = "the password hash of user '" + r.user.name + "' in the database " + why +
                     " (damaged); give a new password with `syncplc user passwd " + r.user.name + "`";
  r.user.created_ns = q.getColumn(3).getInt64();
  r.user.stamp = q.getColumn(4).getInt64();
  return r;
}

constexpr const char* kSelectRow = "SELECT name, role, hash, created_ns, stamp FROM users";

// A stamp no earlier one of this row is likely to have had (2^-64 per change).
std::int64_t new_stamp() {
  std::int64_t s = 0;
  randombytes_buf(&s, sizeof s);
  return s;
}

}  // namespace

std::string check_user_name(std::string_view name) {
  if (name.empty()) return "the user name is empty";
  if (name.size() > kUserNameMaxBytes)
    return "a user name has at most " + std::to_string(kUserNameMaxBytes) + " characters; this one has " +
           std::to_string(name.size());
  for (const char ch : name) {
    const auto c = static_cast<unsigned char>(ch);
    if (!name_char(c))
      return "a user name is made of A-Z a-z 0-9 _ . @ -; this one has " + quoted_char(c);
  }
  return "";
}

std::string check_password(std::string_view password) {
  if (password.size() < kPasswordMinBytes)
    return "a password has at least " + std::to_string(kPasswordMinBytes) + " bytes; this one has " +
           std::to_string(password.size());
  if (password.size() > kPasswordMaxBytes)
    return "a password has at most " + std::to_string(kPasswordMaxBytes) + " bytes; this one has " +
           std::to_string(password.size());
  return "";
}

std::string hash_password(std::string_view password) {
  sodium_ready();
  char out[crypto_pwhash_STRBYTES];
  if (crypto_pwhash_str(out, password.data(), password.size(), kOpsLimit, kMemLimit) != 0) return "";
  return out;
}

std::string_view dummy_password_hash() { return kDummyHash; }

const store::SchemaPart& UserStore::schema() {
  static const store::SchemaPart part{
      "users",
      {"CREATE TABLE users ("
       " name TEXT PRIMARY KEY,"        // 1..64 of A-Z a-z 0-9 _ . @ -
       " role TEXT NOT NULL,"           // viewer, operator, engineer
       " hash TEXT NOT NULL,"           // crypto_pwhash_str: $argon2id$v=19$m=..,t=..,p=..$salt$hash
       " created_ns INTEGER NOT NULL,"  // wall time, ns since 1970 (UTC)
       " changed_ns INTEGER NOT NULL"   // the last change of role or password
       ")",
       // The credential stamp (users.hpp, User::stamp); rows from before it
       // get one each, so the sessions of a restarted server start from them.
       "ALTER TABLE users ADD COLUMN stamp INTEGER NOT NULL DEFAULT 0;"
       " UPDATE users SET stamp = random()"}};
  return part;
}

std::unique_ptr<UserStore> UserStore::open(const std::string& db_path, std::string* error) {
  std::unique_ptr<UserStore> s(new UserStore);
  s->path_ = db_path;
  try {
    sodium_ready();
    const bool memory = db_path == store::kMemoryDatabase;
    bool created = false;
    if (!memory) {
      const fs::path dir = fs::path(db_path).parent_path();
      if (!dir.empty() && !fs::exists(dir)) {
        fs::create_directories(dir);
        fs::permissions(dir, fs::perms::owner_all, fs::perm_options::replace);  // as store::Database::open
      }
      created = !fs::exists(db_path);
    }
    s->db_ = std::make_unique<SQLite::Database>(db_path, SQLite::OPEN_READWRITE | SQLite::OPEN_CREATE);
    s->db_->setBusyTimeout(kUsersBusyTimeoutMs);
    // The journal mode (WAL) is the PLC store's to set; a user written is on disk once add() returns.
    s->db_->exec(std::string("PRAGMA synchronous=") + store::kStoreSynchronous);
    if (created) fs::permissions(db_path, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
    // Two processes making the table at once (`syncplc user` beside a
    // starting server): the later CREATE TABLE fails on the table the other
    // just made; a second look finds it at its version.
    for (int attempt = 0;; ++attempt) {
      try {
        std::string err;
        if (!store::ensure_schema(*s->db_, schema(), &err)) {
          fail(error, "cannot use the database " + db_path + ": " + err);
          return nullptr;
        }
        break;
      } catch (const SQLite::Exception&) {
        if (attempt > 0) throw;
      }
    }
  } catch (const std::exception& e) {
    fail(error, "cannot open the users in the database " + db_path + ": " + e.what());
    return nullptr;
  }
  return s;
}

UserStore::~UserStore() = default;

void UserStore::set_log(std::function<void(const std::string&)> log) { log_ = std::move(log); }

void UserStore::log(const std::string& message) const {
  if (log_) log_(message);
  else std::cerr << "syncplc: users: " << message << "\n";
}

bool UserStore::add(const std::string& name, const std::string& password, Role role, std::string* error) {
  if (std::string why = check_user_name(name); !why.empty()) return fail(error, why);
  if (std::string why = check_password(password); !why.empty()) return fail(error, why);
  const std::string taken = "the user '" + name + "' exists already (change it with `syncplc user passwd` or `role`)";
  try {
    if (exists(name)) return fail(error, taken);  // before the hash, to spare its cost: the insert's key decides
  } catch (const std::exception& e) {
    return fail(error, e.what());
  }
  const std::string hash = hash_password(password);
  if (hash.empty()) return fail(error, "cannot hash the password: Argon2id needs 64 MiB of memory and did not get it");
  try {
    std::lock_guard lock(mutex_);
    const std::int64_t now = store::wall_now_ns();
    SQLite::Statement ins(*db_,
                          "INSERT INTO users (name, role, hash, created_ns, changed_ns, stamp) VALUES (?, ?, ?, ?, ?, ?)");
    ins.bind(1, name);
    ins.bind(2, std::string(role_name(role)));
    ins.bind(3, hash);
    ins.bind(4, now);
    ins.bind(5, now);
    ins.bind(6, new_stamp());
    ins.exec();
  } catch (const SQLite::Exception& e) {
    if (e.getExtendedErrorCode() == SQLITE_CONSTRAINT_PRIMARYKEY) return fail(error, taken);
    return fail(error, "cannot write the user '" + name + "' to " + path_ + ": " + e.what());
  }
  return true;
}

bool UserStore::remove(const std::string& name, std::string* error) {
  try {
    std::lock_guard lock(mutex_);
    SQLite::Statement del(*db_, "DELETE FROM users WHERE name = ?");
    del.bind(1, name);
    if (del.exec() == 0) return fail(error, "there is no user '" + name + "'");
  } catch (const std::exception& e) {
    return fail(error, "cannot remove the user '" + name + "' from " + path_ + ": " + e.what());
  }
  return true;
}

bool UserStore::set_password(const std::string& name, const std::string& password, std::string* error) {
  if (std::string why = check_password(password); !why.empty()) return fail(error, why);
  const std::string none = "there is no user '" + name + "'";
  try {
    if (!exists(name)) return fail(error, none);  // before the hash, to spare its cost: the update's count decides
  } catch (const std::exception& e) {
    return fail(error, e.what());
  }
  const std::string hash = hash_password(password);
  if (hash.empty()) return fail(error, "cannot hash the password: Argon2id needs 64 MiB of memory and did not get it");
  try {
    std::lock_guard lock(mutex_);
    SQLite::Statement up(*db_, "UPDATE users SET hash = ?, changed_ns = ?, stamp = ? WHERE name = ?");
    up.bind(1, hash);
    up.bind(2, store::wall_now_ns());
    up.bind(3, new_stamp());
    up.bind(4, name);
    if (up.exec() == 0) return fail(error, none);
  } catch (const std::exception& e) {
    return fail(error, "cannot write the password of '" + name + "' to " + path_ + ": " + e.what());
  }
  return true;
}

bool UserStore::set_role(const std::string& name, Role role, std::string* error) {
  try {
    std::lock_guard lock(mutex_);
    SQLite::Statement up(*db_, "UPDATE users SET role = ?, changed_ns = ?, stamp = ? WHERE name = ?");
    up.bind(1, std::string(role_name(role)));
    up.bind(2, store::wall_now_ns());
    up.bind(3, new_stamp());
    up.bind(4, name);
    if (up.exec() == 0) return fail(error, "there is no user '" + name + "'");
  } catch (const std::exception& e) {
    return fail(error, "cannot write the role of '" + name + "' to " + path_ + ": " + e.what());
  }
  return true;
}

std::vector<User> UserStore::list() {
  std::vector<Row> rows;
  try {
    std::lock_guard lock(mutex_);
    SQLite::Statement q(*db_, std::string(kSelectRow) + " ORDER BY name");
    while (q.executeStep()) rows.push_back(read_row(q));
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read the users of " + path_ + ": " + e.what());
  }
  std::vector<User> users;
  for (auto& r : rows) {
    if (!r.role_problem.empty()) log(r.role_problem);
    if (!r.hash_problem.empty()) log(r.hash_problem);
    if (r.role_problem.empty()) users.push_back(std::move(r.user));
  }
  return users;
}

std::optional<User> UserStore::find(const std::string& name) {
  std::optional<Row> row;
  try {
    std::lock_guard lock(mutex_);
    SQLite::Statement q(*db_, std::string(kSelectRow) + " WHERE name = ?");
    q.bind(1, name);
    if (q.executeStep()) row = read_row(q);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read the users of " + path_ + ": " + e.what());
  }
  if (!row) return std::nullopt;
  if (!row->role_problem.empty()) {
    log(row->role_problem);
    return std::nullopt;
  }
  return row->user;
}

bool UserStore::exists(const std::string& name) {
  try {
    std::lock_guard lock(mutex_);
    SQLite::Statement q(*db_, "SELECT 1 FROM users WHERE name = ?");
    q.bind(1, name);
    return q.executeStep();
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read the users of " + path_ + ": " + e.what());
  }
}

std::size_t UserStore::count() {
  try {
    std::lock_guard lock(mutex_);
    return static_cast<std::size_t>(db_->execAndGet("SELECT count(*) FROM users").getInt64());
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read the users of " + path_ + ": " + e.what());
  }
}

std::optional<User> UserStore::verify(const std::string& name, const std::string& password) {
  // Refused without a look at the table: the answer cannot depend on which names exist.
  if (!check_user_name(name).empty() || !check_password(password).empty()) return std::nullopt;
  std::optional<Row> row;
  try {
    std::lock_guard lock(mutex_);
    SQLite::Statement q(*db_, std::string(kSelectRow) + " WHERE name = ?");
    q.bind(1, name);
    if (q.executeStep()) row = read_row(q);
  } catch (const std::exception& e) {
    log("cannot read the user '" + name + "' from " + path_ + ": " + e.what());
  }
  bool usable = false;
  if (row) {
    if (!row->role_problem.empty()) log(row->role_problem);
    if (!row->hash_problem.empty()) log(row->hash_problem);
    usable = row->role_problem.empty() && row->hash_problem.empty();
  }
  // One hash whatever happened above (libsodium is ready since open()): no
  // such name, a damaged row and a wrong password take the same time.
  const char* hash = usable ? row->hash.c_str() : kDummyHash;
  const bool match = crypto_pwhash_str_verify(hash, password.data(), password.size()) == 0;
  if (!usable || !match) return std::nullopt;
  return row->user;
}

}  // namespace syncplc::web
