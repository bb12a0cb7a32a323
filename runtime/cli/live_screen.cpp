#include "runtime/cli/live_screen.hpp"

#include <fmt/format.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <iostream>
#include <sstream>

#include "runtime/core/supervisor.hpp"
#include "runtime/modbus/server.hpp"

namespace syncplc::cli {
namespace {

// xterm's alternate screen (1049: with the cursor saved), cursor hidden while on it.
constexpr char kEnter[] = "\x1b[?1049h\x1b[?25l";
constexpr char kLeave[] = "\x1b[?25h\x1b[?1049l";
constexpr char kEllipsis[] = "\xe2\x80\xa6";  // …

// --- the way back from a crash --------------------------------------------------------

constexpr int kFatal[] = {SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL, SIGQUIT};
struct sigaction g_previous[std::size(kFatal)];
std::atomic<bool> g_on_alternate{false};

void leave_on_fatal_signal(int sig) {
  if (g_on_alternate.exchange(false)) {
    ssize_t n = write(STDOUT_FILENO, kLeave, sizeof kLeave - 1);
    (void)n;
  }
  for (std::size_t i = 0; i < std::size(kFatal); ++i)
    if (kFatal[i] == sig) sigaction(sig, &g_previous[i], nullptr);
  raise(sig);  // what the signal did before (a core dump, the sanitizer's report)
}

// Ctrl-Z: the shell's screen while stopped, the alternate one again on fg
// (the next frame redraws it). Where the stop does not happen (an orphaned
// process group ignores it) the screen is taken back at once.
struct sigaction g_previous_tstp;

void on_terminal_stop(int) {
  if (g_on_alternate.load()) {
    ssize_t n = write(STDOUT_FILENO, kLeave, sizeof kLeave - 1);
    (void)n;
  }
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  struct sigaction mine {};
  sigaction(SIGTSTP, &dfl, &mine);
  raise(SIGTSTP);  // stops here until SIGCONT
  sigaction(SIGTSTP, &mine, nullptr);
  if (g_on_alternate.load()) {
    ssize_t n = write(STDOUT_FILENO, kEnter, sizeof kEnter - 1);
    (void)n;
  }
}

void install_fatal_handlers() {
  struct sigaction sa {};
  sa.sa_handler = leave_on_fatal_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_NODEFER;
  for (std::size_t i = 0; i < std::size(kFatal); ++i) sigaction(kFatal[i], &sa, &g_previous[i]);
  sa.sa_flags = SA_RESTART | SA_NODEFER;  // NODEFER: the raise() inside stops the process at once
  sa.sa_handler = on_terminal_stop;
  sigaction(SIGTSTP, &sa, &g_previous_tstp);
}

void restore_fatal_handlers() {
  for (std::size_t i = 0; i < std::size(kFatal); ++i) sigaction(kFatal[i], &g_previous[i], nullptr);
  sigaction(SIGTSTP, &g_previous_tstp, nullptr);
}

std::size_t screen_width() {
  winsize w{};
  if (ioctl(STDOUT_FILENO, TIOCGWINSZ, &w) != 0 || w.ws_col == 0) return 80;
  return std::clamp<std::size_t>(w.ws_col, 40, 240);
}

// Byte offset of the code point that starts column `col` (or the end).
std::size_t byte_at_column(std::string_view s, std::size_t col) {
  std::size_t i = 0, c = 0;
  while (i < s.size()) {
    if ((static_cast<unsigned char>(s[i]) & 0xC0) != 0x80) {
      if (c == col) return i;
      ++c;
    }
    ++i;
  }
  return s.size();
}

std::string value_text(const Tag& t, const Cell& c) {
  if (t.type == IecType::LREAL) return fmt::format("{:.6g}", c.get<double>());
  if (t.type == IecType::REAL) return fmt::format("{:.6g}", c.get<float>());
  return format_value(t.type, c);
}

}  // namespace

std::size_t display_width(std::string_view s) {
  return static_cast<std::size_t>(
      std::count_if(s.begin(), s.end(), [](char ch) { return (static_cast<unsigned char>(ch) & 0xC0) != 0x80; }));
}

std::string shorten_end(std::string_view s, std::size_t width) {
  if (display_width(s) <= width) return std::string(s);
  if (width == 0) return {};
  return std::string(s.substr(0, byte_at_column(s, width - 1))) + kEllipsis;
}

std::string shorten_middle(std::string_view s, std::size_t width) {
  const std::size_t w = display_width(s);
  if (w <= width) return std::string(s);
  if (width < 3) return shorten_end(s, width);
  const std::size_t head = (width - 1) / 2 + (width - 1) % 2, tail = width - 1 - head;
  return std::string(s.substr(0, byte_at_column(s, head))) + kEllipsis + std::string(s.substr(byte_at_column(s, w - tail)));
}

std::string compact_count(std::uint64_t n) {
  if (n < 1000) return std::to_string(n);
  static constexpr const char* kUnit[] = {"k", "M", "G", "T", "P", "E"};
  double v = static_cast<double>(n);
  for (const char* u : kUnit) {
    v /= 1000.0;
    if (v < 9.95) return fmt::format("{:.1f}{}", v, u);
    if (v < 999.5) return fmt::format("{:.0f}{}", v, u);
  }
  return fmt::format("{:.0f}E", v * 1000.0);
}

std::string compact_ns(std::int64_t ns) {
  const double a = std::abs(static_cast<double>(ns));
  if (a < 999.5) return fmt::format("{}ns", ns);
  struct Scale {
    double div;
    const char* unit;
  };
  static constexpr Scale kScale[] = {{1e3, "\xc2\xb5s"}, {1e6, "ms"}, {1e9, "s"}};
  for (const auto& s : kScale) {
    const double v = static_cast<double>(ns) / s.div, av = std::abs(v);
    if (av < 9.995) return fmt::format("{:.2f}{}", v, s.unit);
    if (av < 99.95) return fmt::format("{:.1f}{}", v, s.unit);
    if (av < 999.5 || s.div == 1e9) return fmt::format("{:.0f}{}", v, s.unit);
  }
  return {};
}

std::string render_live_screen(const LiveView& v, std::size_t width) {
  std::ostringstream s;
  auto line = [&](std::string_view text) { s << shorten_end(text, width) << '\n'; };

  line(fmt::format("syncplc run  {}  {:.1f}s   Ctrl-C stops, SIGHUP reloads", shorten_middle(v.project, 30),
                   v.elapsed_s));
  if (!v.reload.empty()) {
    line(v.reload_failed ? "RELOAD FAILED: " + v.reload + "; the running program continues"
                         : "Last reload: " + v.reload);
    for (const auto& d : v.reload_details) line("  " + d);
  }
  line("");
  // 2 + 14 + 6 + 7 + 6 + 6 + 4 + 2×7 + 2×7 + 5 = 78 columns.
  const auto row = [](std::string_view name, std::string_view period, std::string_view scans, std::string_view over,
                      std::string_view skip, std::string_view wd, std::string_view e1, std::string_view e2,
                      std::string_view j1, std::string_view j2, std::string_view state) {
    return fmt::format("  {:<14}{:>6}{:>7}{:>6}{:>6}{:>4}{:>8}{:>7}{:>8}{:>7} {}", shorten_middle(name, 13), period,
                       scans, over, skip, wd, e1, e2, j1, j2, state);
  };
  line(row("task", "period", "scans", "overr", "skip", "wd", "exec", "max", "jitter", "max", ""));
  line(row("", "", "", "", "", "", "mean", "", "p99", "", ""));
  for (const auto& t : v.tasks) {
    const auto& st = t.stats;
    std::string period = format_duration(t.period_ns);  // as the project says it, when short
    if (display_width(period) > 6) period = compact_ns(t.period_ns);
    const bool e = st.exec.count > 0, j = st.jitter.count > 0;
    line(row(t.name, period, compact_count(st.scans), compact_count(st.overruns),
             compact_count(st.skipped), compact_count(st.watchdog_trips),
             e ? compact_ns(static_cast<std::int64_t>(st.exec.mean)) : "-", e ? compact_ns(st.exec.max) : "-",
             j ? compact_ns(st.jitter.p99) : "-", j ? compact_ns(st.jitter.max) : "-", t.state));
  }
  if (!v.modbus_endpoint.empty()) {
    const auto& m = v.modbus;
    std::string codes;
    for (std::size_t i = 1; i < m.by_exception.size(); ++i)
      if (m.by_exception[i]) codes += fmt::format("{}{:02X}:{}", codes.empty() ? "" : " ", i, compact_count(m.by_exception[i]));
    line("");
    line(fmt::format("Modbus {}  clients {}  requests {}  written {}  exceptions {}{}", v.modbus_endpoint,
                     compact_count(m.open), compact_count(m.requests), compact_count(m.values_written),
                     compact_count(m.exceptions), codes.empty() ? "" : " (" + codes + ")"));
  }
  if (!v.store.empty()) {
    if (v.modbus_endpoint.empty()) line("");
    line(v.store);
  }
  if (v.forces) {
    // As PLC programmers expect: a forced program is never mistaken for a free one.
    line("");
    line(fmt::format("FORCED: {} element{} held at forced values{}", v.forces, v.forces == 1 ? "" : "s",
                     v.watched.empty() ? "" : " (F: a watched tag)"));
  }
  if (!v.watched.empty()) {
    line("");
    line("Watched tags");
    for (const auto& w : v.watched) {
      const std::string head = fmt::format("{} {:<20} ", w.forced ? "F" : " ", shorten_middle(w.name, 20));
      const std::string unit = w.unit.empty() ? "" : " " + shorten_end(w.unit, 10);
      const std::size_t room = width > display_width(head) + display_width(unit) ? width - display_width(head) - display_width(unit) : 0;
      line(head + shorten_end(w.value, room) + unit);
    }
  }
  line("");
  line(v.events.empty() ? "Events: none" : "Events (most recent last)");
  for (const auto& e : v.events) line("  " + e);
  return s.str();
}

// --- LiveScreen ------------------------------------------------------------------------

LiveScreen::LiveScreen(std::ostream& os, bool enabled) : os_(os) {
  if (!enabled) return;
  install_fatal_handlers();
  g_on_alternate.store(true);
  os_ << kEnter << std::flush;
  entered_ = true;
}

LiveScreen::~LiveScreen() { leave(); }

void LiveScreen::leave() {
  if (!entered_) return;
  entered_ = false;
  g_on_alternate.store(false);
  os_ << kLeave << std::flush;
  restore_fatal_handlers();
  // The alternate screen took these with it: the normal screen keeps them.
  if (!reload_.empty())
    std::cerr << "syncplc: " << (reload_failed_ ? "last reload FAILED: " : "last reload: ") << reload_ << "\n";
  for (const auto& e : events_) std::cerr << e << "\n";
}

void LiveScreen::add_event(std::string line) {
  events_.push_back(std::move(line));
  while (events_.size() > kEvents) events_.pop_front();
}

void LiveScreen::set_reload_result(bool ok, std::string message, std::vector<std::string> details) {
  char when[16] = "";
  const time_t now = time(nullptr);
  tm local{};
  if (localtime_r(&now, &local)) strftime(when, sizeof when, "%H:%M:%S", &local);
  reload_ = std::string(when) + " " + message;
  reload_failed_ = !ok;
  if (details.size() > kReloadDetails) details.resize(kReloadDetails);
  reload_details_ = ok ? std::vector<std::string>{} : std::move(details);
  add_event(std::string(ok ? "reload: " : "reload failed: ") + message);
}

LiveView LiveScreen::view(Program& p, double elapsed_s, const modbus::Server* server, const Supervisor* supervisor) const {
  LiveView v;
  v.project = p.name + " " + p.version;
  v.elapsed_s = elapsed_s;
  for (std::size_t i = 0; i < p.tasks.size(); ++i) {
    const auto& t = *p.tasks[i];
    LiveView::TaskRow r;
    r.name = t.config().name;
    r.period_ns = t.config().period_ns;
    r.stats = t.stats.summary();
    if (supervisor && supervisor->hung(p.tasks[i].get())) r.state = "HUNG";
    else if (t.stopped()) r.state = "STOP";
    v.tasks.push_back(std::move(r));
  }
  if (server) {
    v.modbus_endpoint = server->endpoint();
    v.modbus = server->counters().summary();
  }
  v.forces = p.force_count();
  const auto forces = v.forces ? p.forces() : std::vector<ForceEntry>{};
  for (const auto& name : p.watch) {
    const Tag* t = p.find_tag(name);
    if (!t) continue;
    std::vector<Cell> cells(t->length);
    p.read_tag(*t, cells.data());
    std::string text;
    for (std::uint32_t i = 0; i < t->length && text.size() < 200; ++i) text += (i ? ", " : "") + value_text(*t, cells[i]);
    const bool forced = std::any_of(forces.begin(), forces.end(), [&](const ForceEntry& f) {
      return f.cell.task == t->owner && f.cell.cell >= t->cell && f.cell.cell - t->cell < t->length;
    });
    v.watched.push_back({name, text, t->unit, forced});
  }
  v.events.assign(events_.begin(), events_.end());
  v.store = store_;
  v.reload = reload_;
  v.reload_failed = reload_failed_;
  v.reload_details = reload_details_;
  return v;
}

void LiveScreen::draw(Program& p, double elapsed_s, const modbus::Server* server, const Supervisor* supervisor) {
  if (!entered_) return;
  const std::string text = render_live_screen(view(p, elapsed_s, server, supervisor), screen_width());
  // Home, each line cleared to its end, the rest below cleared: no flicker of a whole-screen clear.
  std::string out = "\x1b[H";
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t nl = text.find('\n', at);
    out.append(text, at, nl - at);
    out += "\x1b[K\r\n";
    at = nl + 1;
  }
  out += "\x1b[J";
  os_ << out << std::flush;
}

}  // namespace syncplc::cli
