#include "runtime/store/database.hpp"

#include <SQLiteCpp/Statement.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <sqlite3.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "runtime/store/sqlite_result.hpp"

namespace syncplc::store {
namespace fs = std::filesystem;

std::string real_database_path(const std::string& path) {
  if (path == kMemoryDatabase) return path;
  std::error_code ec;
  fs::path p = fs::absolute(path, ec);
  if (ec) return path;
  // The file's own symlinks first, also one to a file not made yet
  // (weakly_canonical leaves a dangling last element as it is).
  for (int hops = 0; hops < 40 && fs::is_symlink(p, ec); ++hops) {
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) break;
    p = target.is_absolute() ? target : p.parent_path() / target;
  }
  const fs::path real = fs::weakly_canonical(p, ec);
  return ec ? p.lexically_normal().string() : real.string();
}

std::string lock_file(const std::string& path) { return real_database_path(path) + ".lock"; }

namespace {

// The lock file keeps the holder's pid, so the refusal can name it. `shown`:
// the path as the caller gave it, for the message. -1 with `error` when
// refused; kNoLock when a read-only store finds no lock file it can open
// (it writes nothing, so it keeps no writer out).
constexpr int kNoLock = -2;
int take_lock(const std::string& real, const std::string& shown, bool read_only, std::string* error) {
  const std::string lf = real + ".lock";
  int fd = ::open(lf.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0 && read_only) fd = ::open(lf.c_str(), O_RDONLY | O_CLOEXEC);  // flock needs no write access
  if (fd < 0) {
    if (read_only) return kNoLock;
    *error = "cannot open the lock file " + lf + ": " + std::strerror(errno);
    return -1;
  }
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    char pid[32] = {};
    const ssize_t n = pread(fd, pid, sizeof pid - 1, 0);
    ::close(fd);
    std::string holder = n > 0 ? std::string(pid, static_cast<std::size_t>(n)) : std::string();
    while (!holder.empty() && (holder.back() == '\n' || holder.back() == ' ')) holder.pop_back();
    if (err == EWOULDBLOCK)
      *error = "the database " + shown + " is in use by another syncplc instance" +
               (holder.empty() ? "" : " (pid " + holder + ")") + "; give this one its own with --db";
    else *error = "cannot lock " + lf + ": " + std::strerror(err);
    return -1;
  }
  const std::string pid = std::to_string(getpid()) + "\n";
  if (ftruncate(fd, 0) == 0 && pwrite(fd, pid.data(), pid.size(), 0) < 0) { /* the pid is only for the message */ }
  return fd;
}

// Why the existing file `real` is not to be written, or "" when it may be.
// A file without any write permission bit is write-protected also for
// root, who could write it anyway: as `rm` and editors treat it.
std::string write_protection(const std::string& real) {
  struct stat st {};
  if (::stat(real.c_str(), &st) != 0) return "";
  if ((st.st_mode & 0222) == 0) return fmt::format("its mode is {:04o}", st.st_mode & 07777);
  if (::access(real.c_str(), W_OK) != 0) {
    if (errno == EROFS) return "its file system is read-only";
    return std::string("this user may not write it (") + std::strerror(errno) + ")";
  }
  return "";
}

// path.corrupt-20261125T031500Z (then .1, .2 ... if taken).
std::string aside_name(const std::string& real) {
  char stamp[32];
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  std::strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%SZ", &tm);
  std::string base = real + ".corrupt-" + stamp, name = base;
  for (int i = 1; fs::exists(name) || fs::exists(name + "-wal") || fs::exists(name + "-shm"); ++i)
    name = base + "." + std::to_string(i);
  return name;
}

std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// The files beside the database before any connection of ours opened it.
// The -shm is kept as bytes: even a read-only connection writes its read
// marks (and may rebuild it from the WAL), and a file moved aside must be
// what was there.
struct Sidecars {
  bool wal = false, shm = false, journal = false;
  std::string shm_bytes;
};
Sidecars sidecars_of(const std::string& real) {
  Sidecars s;
  s.wal = fs::exists(real + "-wal");
  s.journal = fs::exists(real + "-journal");
  s.shm = fs::exists(real + "-shm");
  if (s.shm) s.shm_bytes = read_file(real + "-shm");
  return s;
}

struct Verdict {
  enum class Kind { Sound, Busy, Corrupt, Failed } kind = Kind::Sound;
  std::string why;  // SQLite's message and code, or quick_check's first line
};

Verdict from_exception(const SQLite::Exception& e) {
  const int code = e.getExtendedErrorCode();
  const std::string why = std::string(e.what()) + " (" + result_code_name(code) + ")";
  switch (classify(code)) {
    case SqliteTrouble::Busy: return {Verdict::Kind::Busy, why};
    case SqliteTrouble::Corrupt: return {Verdict::Kind::Corrupt, why};
    case SqliteTrouble::Other: break;
  }
  return {Verdict::Kind::Failed, why};
}

Verdict quick_check(SQLite::Database& db) {
  SQLite::Statement q(db, "PRAGMA quick_check");
  if (!q.executeStep()) return {Verdict::Kind::Corrupt, "quick_check returned nothing"};
  const std::string first = q.getColumn(0).getString();
  if (first == "ok") return {};
  return {Verdict::Kind::Corrupt, "quick_check: " + first};
}

// Checks the existing file through a read-only connection that never
// checkpoints (SQLITE_DBCONFIG_NO_CKPT_ON_CLOSE): the database and its WAL
// are only read, and the WAL is not deleted when it closes.
Verdict check(const std::string& real, int busy_timeout_ms) {
  try {
    SQLite::Database db(real, SQLite::OPEN_READONLY);
    sqlite3_db_config(db.getHandle(), SQLITE_DBCONFIG_NO_CKPT_ON_CLOSE, 1, nullptr);
    db.setBusyTimeout(busy_timeout_ms);
    return quick_check(db);
  } catch (const SQLite::Exception& e) {
    // A hot rollback journal needs a writer to roll it back (the open for
    // writing below does): not a verdict on the file.
    if (e.getExtendedErrorCode() == SQLITE_READONLY_ROLLBACK) return {};
    return from_exception(e);
  }
}

void sync_directory(const std::string& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  (void)fsync(fd);  // the renames survive a power cut
  ::close(fd);
}

// Moves the database and the files that were beside it to `aside`, byte for
// byte; removes the empty -wal and the -shm the check's connection made.
void move_aside(const std::string& real, const std::string& aside, const Sidecars& before) {
  fs::rename(real, aside);
  if (before.wal) fs::rename(real + "-wal", aside + "-wal");
  else fs::remove(real + "-wal");
  if (before.journal) fs::rename(real + "-journal", aside + "-journal");
  if (before.shm) {
    fs::rename(real + "-shm", aside + "-shm");
    // Back to what it was before our check read through it (its read marks).
    std::ofstream f(aside + "-shm", std::ios::binary | std::ios::trunc);
    f.write(before.shm_bytes.data(), static_cast<std::streamsize>(before.shm_bytes.size()));
  } else {
    fs::remove(real + "-shm");
  }
  sync_directory(fs::path(real).parent_path().string());
}

// file:/path?immutable=1: a path in a URI is percent-encoded where it is not
// a plain character.
std::string uri_path(const std::string& path) {
  std::string out;
  for (unsigned char c : path) {
    if (std::isalnum(c) || c == '/' || c == '-' || c == '.' || c == '_' || c == '~') out += static_cast<char>(c);
    else out += fmt::format("%{:02X}", c);
  }
  return out;
}

// A read-only connection to a write-protected database that leaves no file
// behind: without WAL content the main file holds every committed
// transaction, read as an immutable file (no -wal, no -shm, no lock made);
// with WAL content SQLite needs the WAL index, and a -shm it had to make
// is listed in `made` for removal after the close.
std::unique_ptr<SQLite::Database> open_write_protected(const std::string& real, std::vector<std::string>& made) {
  std::error_code ec;
  const bool wal_content = fs::exists(real + "-wal") && fs::file_size(real + "-wal", ec) > 0;
  if (!wal_content)
    return std::make_unique<SQLite::Database>("file:" + uri_path(real) + "?immutable=1",
                                              SQLite::OPEN_READONLY | SQLite::OPEN_URI);
  if (!fs::exists(real + "-shm")) made.push_back(real + "-shm");
  return std::make_unique<SQLite::Database>(real, SQLite::OPEN_READONLY);
}

void set_up(SQLite::Database& db, bool memory) {
  if (!memory) {
    SQLite::Statement wal(db, "PRAGMA journal_mode=WAL");
    if (!wal.executeStep() || wal.getColumn(0).getString() != "wal")
      throw SQLite::Exception("the database does not take WAL journaling", SQLITE_ERROR);
  }
  db.exec(std::string("PRAGMA synchronous=") + kStoreSynchronous);
  db.exec("PRAGMA foreign_keys=ON");
}

std::string busy_message(const std::string& shown, const std::string& why, int timeout_ms) {
  return fmt::format(
      "the database {} is locked by another connection ({}) and stayed locked for {:g} s: nothing was moved or "
      "changed; end the other connection (an sqlite3 shell with a transaction open, a backup) and start again",
      shown, why, timeout_ms / 1000.0);
}

}  // namespace

std::unique_ptr<Database> Database::open(const std::string& path, OpenReport* report, std::string* error,
                                         const OpenOptions& options) {
  OpenReport local;
  OpenReport& r = report ? *report : local;
  r = OpenReport{};
  std::unique_ptr<Database> d(new Database);
  d->path_ = path;
  const bool memory = path == kMemoryDatabase;
  const std::string real = memory ? path : real_database_path(path);
  d->real_path_ = real;
  try {
    if (memory) {
      d->db_ = std::make_unique<SQLite::Database>(path, SQLite::OPEN_READWRITE | SQLite::OPEN_CREATE);
      d->db_->setBusyTimeout(options.busy_timeout_ms);
      set_up(*d->db_, true);
      return d;
    }
    const fs::path dir = fs::path(real).parent_path();
    if (!dir.empty() && !fs::exists(dir)) {
      fs::create_directories(dir);
      fs::permissions(dir, fs::perms::owner_all, fs::perm_options::replace);  // the audit trail is the owner's
    }
    std::error_code ec;
    const bool exists = fs::exists(real, ec) && fs::file_size(real, ec) > 0;
    const std::string protection = exists ? write_protection(real) : std::string();
    if (!protection.empty() && !options.allow_read_only) {
      *error = "the database " + path + " is write-protected (" + protection + ")";
      return nullptr;
    }
    d->read_only_ = !protection.empty();
    d->lock_fd_ = take_lock(real, path, d->read_only_, error);
    if (d->lock_fd_ == -1) {
      r.locked = error->find("in use") != std::string::npos;
      return nullptr;
    }

    if (d->read_only_) {
      r.read_only = true;
      r.read_only_reason = protection;
      d->db_ = open_write_protected(real, d->remove_after_close_);
      d->db_->setBusyTimeout(options.busy_timeout_ms);
      d->db_->exec("PRAGMA query_only=1");  // no write even where the file system would take one (root)
      const Verdict v = quick_check(*d->db_);
      if (v.kind != Verdict::Kind::Sound) {
        // Never moved aside: the owner protected the file as it is.
        *error = "the database " + path + " is write-protected (" + protection + ") and damaged (" + v.why + ")";
        return nullptr;
      }
      return d;
    }

    if (!exists) {
      r.created = true;
    } else {
      const Sidecars before = sidecars_of(real);
      const Verdict v = check(real, options.busy_timeout_ms);
      switch (v.kind) {
        case Verdict::Kind::Sound: break;
        case Verdict::Kind::Busy:
          r.busy = true;
          *error = busy_message(path, v.why, options.busy_timeout_ms);
          return nullptr;
        case Verdict::Kind::Failed:
          // Not a verdict on the file (it cannot be opened or read now): left alone.
          *error = "cannot open the database " + path + ": " + v.why;
          return nullptr;
        case Verdict::Kind::Corrupt: {
          // Never written: kept whole, with its WAL, for whoever looks into it.
          const std::string aside = aside_name(real);
          move_aside(real, aside, before);
          r.created = true;
          r.moved_aside = aside;
          r.problem = v.why;
          break;
        }
      }
    }
    d->db_ = std::make_unique<SQLite::Database>(real, SQLite::OPEN_READWRITE | SQLite::OPEN_CREATE);
    d->db_->setBusyTimeout(options.busy_timeout_ms);
    set_up(*d->db_, false);
    // A file we made is the owner's alone (the event log is an audit trail);
    // an existing one keeps the mode its owner gave it.
    if (r.created) fs::permissions(real, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
  } catch (const SQLite::Exception& e) {
    const Verdict v = from_exception(e);
    if (v.kind == Verdict::Kind::Busy) {
      r.busy = true;
      *error = busy_message(path, v.why, options.busy_timeout_ms);
    } else {
      *error = "cannot open the database " + path + ": " + v.why;
    }
    return nullptr;
  } catch (const std::exception& e) {
    *error = "cannot open the database " + path + ": " + e.what();
    return nullptr;
  }
  return d;
}

std::unique_ptr<Database> Database::open_read_only(const std::string& path, std::string* error) {
  std::unique_ptr<Database> d(new Database);
  d->path_ = path;
  d->real_path_ = real_database_path(path);
  d->read_only_ = true;
  try {
    if (!fs::exists(path)) {
      *error = "no database at " + path;
      return nullptr;
    }
    // A write-protected file has no writer beside the reader (run opens it
    // read-only too): read so that no -wal or -shm is left beside it,
    // which would stop the next writer once the file is writable again.
    if (!write_protection(d->real_path_).empty())
      d->db_ = open_write_protected(d->real_path_, d->remove_after_close_);
    else
      d->db_ = std::make_unique<SQLite::Database>(path, SQLite::OPEN_READONLY);
    d->db_->setBusyTimeout(kBusyTimeoutMs);
  } catch (const std::exception& e) {
    *error = "cannot read the database " + path + ": " + e.what();
    return nullptr;
  }
  return d;
}

Database::~Database() {
  db_.reset();  // closes (and checkpoints, if it writes) before the lock goes
  for (const auto& f : remove_after_close_) {
    std::error_code ec;
    fs::remove(f, ec);
  }
  if (lock_fd_ >= 0) ::close(lock_fd_);
}

}  // namespace syncplc::store
