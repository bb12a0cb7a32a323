#include "runtime/store/database.hpp"

#include <SQLiteCpp/Statement.h>
#include <fcntl.h>
#include <sqlite3.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>

namespace syncplc::store {
namespace fs = std::filesystem;

std::string lock_file(const std::string& path) { return path + ".lock"; }

namespace {

// The lock file keeps the holder's pid, so the refusal can name it.
int take_lock(const std::string& path, std::string* error) {
  const std::string lf = lock_file(path);
  const int fd = ::open(lf.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0) {
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
      *error = "the database " + path + " is in use by another syncplc instance" +
               (holder.empty() ? "" : " (pid " + holder + ")") + "; give this one its own with --db";
    else *error = "cannot lock " + lf + ": " + std::strerror(err);
    return -1;
  }
  const std::string pid = std::to_string(getpid()) + "\n";
  if (ftruncate(fd, 0) == 0 && pwrite(fd, pid.data(), pid.size(), 0) < 0) { /* the pid is only for the message */ }
  return fd;
}

// path.corrupt-20261125T031500Z (then .1, .2 ... if taken).
std::string aside_name(const std::string& path) {
  char stamp[32];
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  std::strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%SZ", &tm);
  std::string base = path + ".corrupt-" + stamp, name = base;
  for (int i = 1; fs::exists(name) || fs::exists(name + "-wal"); ++i) name = base + "." + std::to_string(i);
  return name;
}

// The file's trouble, or "" when SQLite finds it sound.
std::string check(const std::string& path) {
  try {
    SQLite::Database db(path, SQLite::OPEN_READWRITE);
    SQLite::Statement q(db, "PRAGMA quick_check");
    if (!q.executeStep()) return "quick_check returned nothing";
    std::string first = q.getColumn(0).getString();
    return first == "ok" ? std::string() : "quick_check: " + first;
  } catch (const SQLite::Exception& e) {
    return e.what();
  }
}

void set_up(SQLite::Database& db, bool memory) {
  db.setBusyTimeout(5000);  // readers checkpointing beside the writer
  if (!memory) {
    SQLite::Statement wal(db, "PRAGMA journal_mode=WAL");
    if (!wal.executeStep() || wal.getColumn(0).getString() != "wal")
      throw SQLite::Exception("the database does not take WAL journaling", SQLITE_ERROR);
  }
  db.exec(std::string("PRAGMA synchronous=") + kStoreSynchronous);
  db.exec("PRAGMA foreign_keys=ON");
}

}  // namespace

std::unique_ptr<Database> Database::open(const std::string& path, OpenReport* report, std::string* error) {
  OpenReport local;
  OpenReport& r = report ? *report : local;
  r = OpenReport{};
  std::unique_ptr<Database> d(new Database);
  d->path_ = path;
  const bool memory = path == kMemoryDatabase;
  try {
    if (!memory) {
      const fs::path dir = fs::path(path).parent_path();
      if (!dir.empty() && !fs::exists(dir)) {
        fs::create_directories(dir);
        fs::permissions(dir, fs::perms::owner_all, fs::perm_options::replace);  // the audit trail is the owner's
      }
      d->lock_fd_ = take_lock(path, error);
      if (d->lock_fd_ < 0) {
        r.locked = error->find("in use") != std::string::npos;
        return nullptr;
      }
      std::error_code ec;
      const bool exists = fs::exists(path, ec) && fs::file_size(path, ec) > 0;
      if (!exists) {
        r.created = true;
      } else if (std::string why = check(path); !why.empty()) {
        // Never write to a bad file: keep it whole for whoever looks into it.
        const std::string aside = aside_name(path);
        fs::rename(path, aside);
        for (const char* suffix : {"-wal", "-shm"})
          if (fs::exists(path + suffix)) fs::rename(path + suffix, aside + suffix);
        r.created = true;
        r.moved_aside = aside;
        r.problem = why;
      }
    }
    d->db_ = std::make_unique<SQLite::Database>(path, SQLite::OPEN_READWRITE | SQLite::OPEN_CREATE);
    set_up(*d->db_, memory);
    if (!memory) fs::permissions(path, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
  } catch (const std::exception& e) {
    *error = "cannot open the database " + path + ": " + e.what();
    return nullptr;
  }
  return d;
}

std::unique_ptr<Database> Database::open_read_only(const std::string& path, std::string* error) {
  std::unique_ptr<Database> d(new Database);
  d->path_ = path;
  try {
    if (!fs::exists(path)) {
      *error = "no database at " + path;
      return nullptr;
    }
    d->db_ = std::make_unique<SQLite::Database>(path, SQLite::OPEN_READONLY);
    d->db_->setBusyTimeout(5000);
  } catch (const std::exception& e) {
    *error = "cannot read the database " + path + ": " + e.what();
    return nullptr;
  }
  return d;
}

Database::~Database() {
  db_.reset();  // closes (and checkpoints) before the lock goes
  if (lock_fd_ >= 0) ::close(lock_fd_);
}

}  // namespace syncplc::store
