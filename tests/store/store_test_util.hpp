// Helpers of the store tests: a fresh directory per test, the sqlite3 shell
// (Debian's) as a reader and as a second process holding a lock, and
// `syncplc run` as a child process.
#pragma once

#include <fcntl.h>
#include <grp.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "runtime/store/database.hpp"

namespace syncplc::store::testing {

// An empty directory of this process: /tmp/syncplc-store-<pid>/<name>.
inline std::string fresh_dir(const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("syncplc-store-" + std::to_string(getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

// What the sqlite3 shell (Debian's, read-only) prints for `sql` on `db`,
// stderr included, without the trailing newlines.
inline std::string sqlite_shell(const std::string& db, const std::string& sql) {
  const std::string cmd = "sqlite3 -readonly '" + db + "' \"" + sql + "\" 2>&1";
  std::string out;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    char buf[4096];
    while (std::size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
    pclose(p);
  }
  while (!out.empty() && out.back() == '\n') out.pop_back();
  return out;
}

// The sqlite3 shell writing `input` (SQL and dot-commands) to `db` and
// ending: what it printed. Nothing of ours touches the files.
inline std::string sqlite_shell_script(const std::string& db, const std::string& input) {
  const std::string script = db + ".script.sql";
  std::ofstream(script) << input;
  const std::string cmd = "sqlite3 '" + db + "' < '" + script + "' 2>&1";
  std::string out;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    char buf[4096];
    while (std::size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
    pclose(p);
  }
  std::remove(script.c_str());
  return out;
}

inline std::string read_all(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// A second process on the database: the sqlite3 shell, left open after
// running `sql` (e.g. "PRAGMA locking_mode=EXCLUSIVE; BEGIN EXCLUSIVE;"), so
// it holds whatever lock that took until release() (its stdin closes and it
// ends; an open transaction is rolled back).
class ShellHolding {
 public:
  ShellHolding(const std::string& db, const std::string& sql) {
    int in[2], out[2];
    if (pipe(in) != 0 || pipe(out) != 0) return;
    pid_ = fork();
    if (pid_ == 0) {
      dup2(in[0], 0);
      dup2(out[1], 1);
      dup2(out[1], 2);
      close(in[0]), close(in[1]), close(out[0]), close(out[1]);
      execlp("sqlite3", "sqlite3", db.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    close(in[0]);
    close(out[1]);
    to_ = in[1];
    from_ = out[0];
    const std::string script = sql + "\nSELECT 'holding';\n";
    if (write(to_, script.data(), script.size()) < 0) return;
    // Until the shell says it ran the SQL (or it ended: then it holds nothing).
    for (;;) {
      pollfd p{from_, POLLIN, 0};
      if (poll(&p, 1, 30000) <= 0) break;
      char buf[512];
      const ssize_t n = read(from_, buf, sizeof buf);
      if (n <= 0) break;
      said_.append(buf, static_cast<std::size_t>(n));
      if (said_.find("holding") != std::string::npos) {
        holding_ = true;
        break;
      }
    }
  }
  ~ShellHolding() { release(); }
  ShellHolding(const ShellHolding&) = delete;
  ShellHolding& operator=(const ShellHolding&) = delete;

  bool holding() const { return holding_; }
  const std::string& said() const { return said_; }
  void release() {
    if (to_ >= 0) close(to_);
    to_ = -1;
    if (pid_ > 0) waitpid(pid_, nullptr, 0);
    pid_ = -1;
    if (from_ >= 0) close(from_);
    from_ = -1;
    holding_ = false;
  }

 private:
  pid_t pid_ = -1;
  int to_ = -1, from_ = -1;
  bool holding_ = false;
  std::string said_;
};

// `syncplc ARGS...` as a child process, its stdout and stderr together in
// `out_file`; as the user `uid` (and group `gid`) when uid >= 0 (the test
// runs as root). Returns its pid.
inline pid_t spawn_syncplc(const std::vector<std::string>& args, const std::string& out_file, int uid = -1, int gid = -1) {
  // Another user may not reach the build tree (a clone in a 0700 mktemp
  // directory): that user runs a copy of the binary beside its output.
  std::string binary = SYNCPLC_BINARY;
  if (uid >= 0) {
    namespace fs = std::filesystem;
    const fs::path copy = fs::path(out_file).parent_path() / "syncplc";
    if (!fs::exists(copy)) fs::copy_file(SYNCPLC_BINARY, copy);
    fs::permissions(copy, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                              fs::perms::others_read | fs::perms::others_exec, fs::perm_options::replace);
    binary = copy.string();
  }
  const pid_t child = fork();
  if (child == 0) {
    const int fd = ::open(out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 1);
    dup2(fd, 2);
    if (uid >= 0) {
      if (setgroups(0, nullptr) != 0 || setgid(static_cast<gid_t>(gid)) != 0 || setuid(static_cast<uid_t>(uid)) != 0) _exit(126);
      setenv("HOME", std::filesystem::path(out_file).parent_path().c_str(), 1);
    }
    std::vector<char*> argv;
    argv.push_back(binary.data());
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(binary.c_str(), argv.data());
    _exit(127);
  }
  return child;
}

// Its exit status once it ended; 128 + n when ended by signal n.
inline int wait_syncplc(pid_t child) {
  int status = 0;
  waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

struct RunOutput {
  int status = -1;
  std::string output;  // stdout and stderr
};
inline RunOutput run_syncplc(const std::vector<std::string>& args, const std::string& out_file, int uid = -1, int gid = -1) {
  RunOutput r;
  r.status = wait_syncplc(spawn_syncplc(args, out_file, uid, gid));
  r.output = read_all(out_file);
  return r;
}

// Database::open(path) in another process (flock is per open file
// description: a fork that opens again is a second instance): "opened", or
// "locked: " / "failed: " and the error.
inline std::string open_in_another_process(const std::string& path) {
  int pipefd[2];
  if (pipe(pipefd) != 0) return "no pipe";
  const pid_t child = fork();
  if (child == 0) {
    OpenReport r;
    std::string e;
    auto second = Database::open(path, &r, &e);
    const std::string out = (second ? "opened" : (r.locked ? "locked: " : "failed: ") + e);
    if (write(pipefd[1], out.data(), out.size()) < 0) _exit(2);
    _exit(0);
  }
  close(pipefd[1]);
  std::string got;
  char buf[512];
  for (ssize_t n; (n = read(pipefd[0], buf, sizeof buf)) > 0;) got.append(buf, static_cast<std::size_t>(n));
  close(pipefd[0]);
  waitpid(child, nullptr, 0);
  return got;
}

}  // namespace syncplc::store::testing
