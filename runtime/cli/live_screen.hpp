// The live screen of `syncplc run` on a terminal. It uses the terminal's
// alternate screen (as top and less do) and gives the normal screen back on
// every way out: a normal end, SIGINT/SIGTERM (taken by the main thread, so
// that is a normal end), an error unwinding out of cmd_run (the destructor),
// the exit that leaves a stuck scan thread behind (leave() before _Exit), and
// a crash (SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL, SIGQUIT: a handler writes
// the escape sequence with write(2), then the signal does what it did before);
// Ctrl-Z gives it back while the process is stopped and takes it again on fg.
//
// What it shows fits 80 columns: compact counts (1.2k, 3.4M), times with
// three significant digits (12.3µs, 1.23ms), long names shortened in the
// middle. Events are kept, the most recent kEvents of them, and so is the
// result of the last online change: it stays until the next one, and a
// failed one stays (with its first errors) until one succeeds.
//
// The screen reads statistics (atomics) and published snapshots only: it
// never touches a task's image and never takes a lock a scan could wait on.
// Rendering is a pure function of a LiveView, so it is tested without a terminal.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/core/program.hpp"
#include "runtime/modbus/counters.hpp"

namespace syncplc {
class Supervisor;
namespace modbus {
class Server;
}
}  // namespace syncplc

namespace syncplc::cli {

// Everything one frame of the screen shows, as plain data.
struct LiveView {
  std::string project;  // name and version
  double elapsed_s = 0;
  struct TaskRow {
    std::string name;
    std::int64_t period_ns = 0;
    TaskStats::Summary stats{};
    std::string state;  // "", "STOP" (stopped by its watchdog), "HUNG" (a scan that did not end)
  };
  std::vector<TaskRow> tasks;
  std::string modbus_endpoint;  // "" when no server runs
  modbus::Counters::Summary modbus{};
  struct Watched {
    std::string name, value, unit;
    bool forced = false;  // an element is forced: marked "F"
  };
  std::size_t forces = 0;  // active forces (Program::force_count)
  std::vector<Watched> watched;
  std::string store;                // the PLC database's state (store_status.hpp), "" for none
  std::vector<std::string> events;  // oldest first
  std::string reload;               // the last online change's result, "" before the first
  bool reload_failed = false;
  std::vector<std::string> reload_details;  // a failed reload's first errors
};

// The screen as text, one line per '\n', none wider than `width` columns.
std::string render_live_screen(const LiveView& view, std::size_t width = 80);

// Columns a UTF-8 string takes (one per code point: the screen uses no wide characters).
std::size_t display_width(std::string_view s);
// At most `width` columns: the middle replaced by "…" (names), or the end (messages).
std::string shorten_middle(std::string_view s, std::size_t width);
std::string shorten_end(std::string_view s, std::size_t width);
// 999, 1.2k, 12k, 123k, 1.2M, ...
std::string compact_count(std::uint64_t n);
// Three significant digits: 850ns, 1.23µs, 12.3µs, 123µs, 1.23ms, ..., 1.23s.
std::string compact_ns(std::int64_t ns);

class LiveScreen {
 public:
  static constexpr std::size_t kEvents = 8;
  static constexpr std::size_t kReloadDetails = 3;

  // enabled: take the terminal's alternate screen now (and give it back in leave()).
  LiveScreen(std::ostream& os, bool enabled);
  ~LiveScreen();
  LiveScreen(const LiveScreen&) = delete;
  LiveScreen& operator=(const LiveScreen&) = delete;

  bool enabled() const { return entered_; }
  // Gives the normal screen back (once), then prints the events it kept on
  // stderr, which the alternate screen took with it.
  void leave();

  void add_event(std::string line);
  // An online change's result, for the lead's reload code: `message` is one
  // line ("reloaded: 12 kept, 1 new" / "3 errors in the project file");
  // `details` are the first errors of a failed one. Also an event.
  void set_reload_result(bool ok, std::string message, std::vector<std::string> details = {});

  // The store's line (store_status_line), shown under the Modbus line.
  void set_store(std::string line) { store_ = std::move(line); }

  LiveView view(Program& p, double elapsed_s, const modbus::Server* server, const Supervisor* supervisor) const;
  // Renders a frame at the terminal's width and draws it over the last one.
  void draw(Program& p, double elapsed_s, const modbus::Server* server, const Supervisor* supervisor);

 private:
  std::ostream& os_;
  bool entered_ = false;
  std::deque<std::string> events_;
  std::string reload_;
  std::string store_;
  bool reload_failed_ = false;
  std::vector<std::string> reload_details_;
};

}  // namespace syncplc::cli
