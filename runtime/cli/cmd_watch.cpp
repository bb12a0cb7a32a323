// syncplc watch: live values from GET /stream (Server-Sent Events), each
// with its quality when it is not good (stale, task stopped, driver not ok,
// forced) and an unknown ref's reason in place of its value. On a
// terminal the refs' lines are drawn over the last ones, under a line with
// the values' time; otherwise one plain line per update, for a pipe or a
// log. The stream runs on a thread of its own so that Ctrl-C (or SIGTERM),
// taken by this thread, ends it at once even while the PLC sends nothing.
#include <signal.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

#include <fmt/format.h>

#include <atomic>
#include <cstdio>
#include <exception>
#include <iostream>
#include <map>
#include <thread>

#include "runtime/cli/api_client.hpp"
#include "runtime/cli/commands.hpp"
#include "runtime/cli/live_screen.hpp"
#include "runtime/cli/online_values.hpp"
#include "runtime/cli/ref_units.hpp"
#include "runtime/cli/sse_reader.hpp"

namespace syncplc::cli {
namespace {

using nlohmann::json;

// A t_ns this large is wall time (after 2001); a smaller one counts from
// some start (a monotonic clock) and is shown in seconds.
constexpr double kWallTimeFrom = 1e18;

std::string time_text(const json& t_ns) {
  if (!t_ns.is_number()) return "--:--:--.---";
  const double ns = t_ns.get<double>();
  if (ns < kWallTimeFrom) return fmt::format("t={:.3f}s", ns / 1e9);
  const auto ms = static_cast<std::int64_t>(ns / 1e6);
  const std::time_t secs = static_cast<std::time_t>(ms / 1000);
  std::tm tm{};
  localtime_r(&secs, &tm);
  char hms[16];
  std::strftime(hms, sizeof hms, "%H:%M:%S", &tm);
  return fmt::format("{}.{:03}", hms, ms % 1000);
}

// A value's quality as the stream sends it ({"q", "age_ns"}): "" when good,
// else what an operator must know: "stale 1.52 s", "task stopped",
// "driver not ok", "forced".
std::string quality_text(const json& q) {
  if (!q.is_object() || !q.contains("q") || !q["q"].is_string()) return {};
  const std::string word = q["q"].get<std::string>();
  if (word == "good") return {};
  if (word == "stale") {
    const double age = q.value("age_ns", 0.0) / 1e9;
    return age > 0 ? fmt::format("stale {:.3g} s", age) : "stale, no scan yet";
  }
  if (word == "task_stopped") return "task stopped";
  if (word == "driver_not_ok") return "driver not ok";
  return word;
}

std::size_t terminal_width() {
  winsize w{};
  if (ioctl(STDOUT_FILENO, TIOCGWINSZ, &w) == 0 && w.ws_col > 0) return w.ws_col;
  return 80;
}

class WatchOutput {
 public:
  WatchOutput(const std::vector<std::string>& refs, std::map<std::string, std::string> units, bool terminal)
      : refs_(refs), units_(std::move(units)), terminal_(terminal) {
    for (const auto& r : refs_) ref_width_ = std::max(ref_width_, display_width(r));
    if (terminal_) std::cout << "\x1b[?25l" << std::flush;  // no cursor blinking over the values
  }
  ~WatchOutput() {
    if (terminal_) std::cout << "\x1b[?25h" << std::flush;
  }

  void show(const json& update) {
    const json values = update.value("values", json::object());
    const json forced = update.value("forced", json::object());
    const json quality = update.value("quality", json::object());
    const json errors = update.value("errors", json::object());
    auto ref_text = [&](const std::string& ref) {
      // An unknown ref (renamed by an online change): why, in place of a value.
      if (errors.contains(ref) && errors[ref].is_string()) return "? (" + errors[ref].get<std::string>() + ")";
      std::string s = format_value(values.value(ref, json()));
      if (!units_.at(ref).empty()) s += " " + units_.at(ref);
      const std::string q = quality_text(quality.value(ref, json()));
      if (!q.empty()) s += " (" + q + ")";
      else if (any_forced(forced.value(ref, json()))) s += " (forced)";
      return s;
    };
    if (!terminal_) {
      std::string line = time_text(update.value("t_ns", json()));
      for (const auto& r : refs_) line += "  " + r + " = " + ref_text(r);
      std::cout << line << "\n" << std::flush;  // a pipe sees each update when it comes
      return;
    }
    const std::size_t width = terminal_width();
    std::string frame;
    if (drawn_) frame += fmt::format("\r\x1b[{}A", refs_.size() + 1);  // back to the time line
    auto put = [&](const std::string& line) { frame += "\x1b[2K" + shorten_end(line, width - 1) + "\n"; };
    put(time_text(update.value("t_ns", json())) + "  (Ctrl-C ends)");
    for (const auto& r : refs_)
      put(r + std::string(ref_width_ - display_width(r), ' ') + " = " + ref_text(r));
    std::cout << frame << std::flush;
    drawn_ = true;
  }

 private:
  std::vector<std::string> refs_;
  std::map<std::string, std::string> units_;
  bool terminal_;
  bool drawn_ = false;
  std::size_t ref_width_ = 0;
};

// What the stream thread found: how many updates, and why it ended.
struct StreamEnd {
  int updates = 0;
  std::string error;  // an `event: error` of the server
  std::exception_ptr failure;
};

}  // namespace

int cmd_watch(const WatchOptions& w, const OnlineOptions& o) {
  return run_online("watch", [&]() -> int {
    auto api = connect_api(o);
    const std::string refs = refs_query(w.refs);
    api->call("GET", "/values?refs=" + refs);  // an unknown ref: 404 names it, before any live output
    WatchOutput out(w.refs, ref_units(*api, w.refs), isatty(STDOUT_FILENO) == 1);

    // SIGINT and SIGTERM are taken by sigtimedwait below: blocked here, and
    // so in the stream thread, which inherits the mask.
    sigset_t stop_signals, old_mask;
    sigemptyset(&stop_signals);
    sigaddset(&stop_signals, SIGINT);
    sigaddset(&stop_signals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &stop_signals, &old_mask);

    StreamEnd end;
    std::atomic<bool> done{false};
    std::thread reader([&] {
      SseReader sse;
      try {
        api->stream("/stream?refs=" + refs + "&rate=" + std::to_string(w.rate), [&](std::string_view chunk) {
          for (const SseEvent& e : sse.feed(chunk)) {
            if (e.type == "error") {
              const json j = json::parse(e.data, nullptr, false);
              end.error = j.is_object() && j.contains("error") ? j["error"].get<std::string>() : e.data;
              return false;
            }
            if (e.type != "values") continue;
            out.show(json::parse(e.data));
            if (w.count && ++end.updates >= *w.count) return false;
          }
          return true;
        });
      } catch (...) {
        end.failure = std::current_exception();
      }
      done = true;
    });
    bool interrupted = false;
    const timespec poll{0, 100'000'000};
    while (!done) {
      if (sigtimedwait(&stop_signals, nullptr, &poll) > 0) {
        interrupted = true;
        api->stop();
        break;
      }
    }
    reader.join();
    pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
    if (interrupted) return kExitOk;
    if (end.failure) std::rethrow_exception(end.failure);
    if (!end.error.empty()) throw ApiError(kExitUnreachable, "the PLC ended the live stream: " + end.error);
    if (w.count && end.updates >= *w.count) return kExitOk;
    throw ApiError(kExitUnreachable, "the live stream from " + api->url() + " ended (has syncplc run stopped?)");
  });
}

}  // namespace syncplc::cli
