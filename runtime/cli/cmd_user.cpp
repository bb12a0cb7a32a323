// `syncplc user add|passwd|role|remove|list`: the users of the HTTP API and
// the HMI (docs/user-guide.md, "Users of the HTTP API and the HMI"), in the
// database `run` uses. It writes through its own connection, without the
// instance lock, so it works beside a running PLC (runtime/web/users.hpp).
//
// A password is never an argument (it would show in `ps` and the shell's
// history): it is asked twice on the terminal without echo, or read as one
// line from standard input with --password-stdin.
#include <fmt/format.h>
#include <signal.h>
#include <sodium.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <iterator>
#include <optional>

#include "runtime/cli/commands.hpp"
#include "runtime/plc/store_link.hpp"
#include "runtime/store/database.hpp"
#include "runtime/web/users.hpp"

namespace syncplc::cli {
using namespace plc;  // the PLC instance's database paths and stored versions (runtime/plc)

namespace {

int refuse(const std::string& why) {
  std::cerr << "syncplc: user: " << why << "\n";
  return kExitInvalid;
}

// A string that holds a password: wiped when it goes (room for the longest
// one is taken first, so no copy is left behind by a reallocation).
struct Secret {
  std::string text;
  Secret() { text.reserve(2 * web::kPasswordMaxBytes); }
  Secret(const Secret&) = delete;
  Secret& operator=(const Secret&) = delete;
  ~Secret() { sodium_memzero(text.data(), text.size()); }
};

// The terminal's settings while echo is off, put back by the signal that
// ends the process meanwhile (Ctrl-C at the prompt must not leave a shell
// that shows nothing typed).
termios g_saved_terminal;
volatile sig_atomic_t g_echo_off = 0;

extern "C" void restore_terminal_and_die(int sig) {
  if (g_echo_off) tcsetattr(STDIN_FILENO, TCSAFLUSH, &g_saved_terminal);
  signal(sig, SIG_DFL);
  raise(sig);
}

constexpr int kEndingSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};

// One line typed on the terminal without echo, into `line`.
bool ask_without_echo(const char* prompt, std::string& line, std::string* error) {
  if (tcgetattr(STDIN_FILENO, &g_saved_terminal) != 0) {
    *error = "cannot read the terminal's settings to turn its echo off";
    return false;
  }
  struct sigaction die {}, before[std::size(kEndingSignals)];
  die.sa_handler = restore_terminal_and_die;
  sigemptyset(&die.sa_mask);
  for (std::size_t i = 0; i < std::size(kEndingSignals); ++i) sigaction(kEndingSignals[i], &die, &before[i]);
  termios quiet = g_saved_terminal;
  quiet.c_lflag &= ~static_cast<tcflag_t>(ECHO);
  quiet.c_lflag |= ECHONL;  // the Enter still moves to the next line
  g_echo_off = 1;
  bool ok = false;
  if (tcsetattr(STDIN_FILENO, TCSAFLUSH, &quiet) != 0) {
    *error = "cannot turn the terminal's echo off";
  } else {
    std::cerr << prompt << std::flush;
    ok = static_cast<bool>(std::getline(std::cin, line));
    if (!ok) *error = "no password typed (end of input)";
    tcsetattr(STDIN_FILENO, TCSAFLUSH, &g_saved_terminal);
  }
  g_echo_off = 0;
  for (std::size_t i = 0; i < std::size(kEndingSignals); ++i) sigaction(kEndingSignals[i], &before[i], nullptr);
  return ok;
}

// The new password: asked twice on a terminal, or one line of standard
// input with --password-stdin (its line end removed).
bool read_password(bool from_stdin, Secret& password, std::string* error) {
  if (from_stdin) {
    if (!std::getline(std::cin, password.text) && password.text.empty()) {
      *error = "--password-stdin: no password on standard input";
      return false;
    }
    if (!password.text.empty() && password.text.back() == '\r') password.text.pop_back();  // a CRLF line end
    return true;
  }
  if (!isatty(STDIN_FILENO)) {
    *error = "standard input is not a terminal to ask the password on; give it as one line with --password-stdin";
    return false;
  }
  Secret again;
  if (!ask_without_echo("password: ", password.text, error)) return false;
  if (!ask_without_echo("the same password again: ", again.text, error)) return false;
  if (password.text != again.text) {
    *error = "the two passwords differ; nothing was changed";
    return false;
  }
  return true;
}

std::string created_utc(std::int64_t ns) {
  const time_t s = static_cast<time_t>(ns / 1'000'000'000);
  tm t{};
  gmtime_r(&s, &t);
  char buf[32];
  strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S", &t);
  return buf;
}

std::optional<web::Role> role_of(const std::string& text, std::string* error) {
  auto r = web::parse_role(text);
  if (!r) *error = "unknown role '" + text + "': viewer, operator or engineer";
  return r;
}

int list_users(web::UserStore& users) {
  const auto all = users.list();
  if (all.empty()) {
    std::cout << "no users in " << users.path() << "; add the first with: syncplc user add NAME --role engineer\n";
    return kExitOk;
  }
  std::cout << fmt::format("{:<24}  {:<8}  {}\n", "name", "role", "created (UTC)");
  for (const auto& u : all)
    std::cout << fmt::format("{:<24}  {:<8}  {}\n", u.name, web::role_name(u.role), created_utc(u.created_ns));
  return kExitOk;
}

}  // namespace

int cmd_user(const UserOptions& o) {
  std::string err;
  // Everything the command line says is checked before a password is asked.
  std::optional<web::Role> role;
  if (o.action == "add" || o.action == "role") {
    role = role_of(o.role, &err);
    if (!role) return refuse(err);
  }
  if (o.action == "add")
    if (std::string why = web::check_user_name(o.name); !why.empty()) return refuse(why);

  store::StoreSettings settings;
  if (!o.project.empty() && o.db.empty()) {
    auto r = load_or_report(o.project, LoadOptions{});
    if (!r.ok()) return refuse("the project " + o.project + " does not load, so its store: path is not known; "
                               "name the database with --db");
    settings = r.store;
  }
  const std::string path = database_path(o.db, settings, o.project);
  // Only add makes a database: a mistyped --db must not leave an empty one behind.
  if (o.action != "add" && path != store::kMemoryDatabase && !std::filesystem::exists(path)) {
    if (o.action != "list") return refuse("there is no user '" + o.name + "': no database at " + path);
    std::cout << "no users: no database at " << path
              << " yet; add the first with: syncplc user add NAME --role engineer\n";
    return kExitOk;
  }
  auto users = web::UserStore::open(path, &err);
  if (!users) return refuse(err);
  users->set_log([](const std::string& m) { std::cerr << "syncplc: user: " << m << "\n"; });  // damaged rows

  try {
    if (o.action == "list") return list_users(*users);
    if (o.action == "remove") {
      if (!users->remove(o.name, &err)) return refuse(err);
      std::cout << "user '" << o.name << "' removed from " << path << "\n";
      return kExitOk;
    }
    if (o.action == "role") {
      if (!users->set_role(o.name, *role, &err)) return refuse(err);
      std::cout << "user '" << o.name << "' is now " << web::role_name(*role) << " in " << path << "\n";
      return kExitOk;
    }
    if (o.action == "add" || o.action == "passwd") {
      const bool there = users->exists(o.name);
      if (o.action == "add" && there) return refuse("the user '" + o.name + "' exists already (change it with "
                                                    "`syncplc user passwd` or `role`)");
      if (o.action == "passwd" && !there) return refuse("there is no user '" + o.name + "' in " + path);
      Secret password;
      if (!read_password(o.password_stdin, password, &err)) return refuse(err);
      if (o.action == "add") {
        if (!users->add(o.name, password.text, *role, &err)) return refuse(err);
        std::cout << "user '" << o.name << "' added as " << web::role_name(*role) << " to " << path << "\n";
      } else {
        if (!users->set_password(o.name, password.text, &err)) return refuse(err);
        std::cout << "password of '" << o.name << "' changed in " << path << "\n";
      }
      return kExitOk;
    }
  } catch (const std::exception& e) {  // a database that cannot be read (UserStore::list, exists)
    return refuse(e.what());
  }
  return refuse("unknown action '" + o.action + "': add, passwd, role, remove or list");
}

}  // namespace syncplc::cli
