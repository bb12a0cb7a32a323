// The live screen of `syncplc run`: rendering as a pure function (80 columns
// for the four-axis demo, events and reload results kept), the compact number
// formats, and the alternate screen given back on every way out of the real
// binary on a pseudo-terminal.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <pty.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <sstream>
#include <thread>

#include "runtime/cli/live_screen.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "tests/support/cli_runner.hpp"
#include "tests/support/test_blocks.hpp"

namespace syncplc::cli {
namespace {

const std::string kSrc = SYNCPLC_SOURCE_DIR;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> v;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) v.push_back(l);
  return v;
}

void expect_fits(const std::string& text, std::size_t width) {
  for (const auto& l : lines_of(text)) EXPECT_LE(display_width(l), width) << "[" << l << "]";
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(LiveScreenFormat, CompactCountsAndTimes) {
  EXPECT_EQ(compact_count(0), "0");
  EXPECT_EQ(compact_count(999), "999");
  EXPECT_EQ(compact_count(1234), "1.2k");
  EXPECT_EQ(compact_count(9960), "10k");
  EXPECT_EQ(compact_count(123456), "123k");
  EXPECT_EQ(compact_count(999'600), "1.0M");
  EXPECT_EQ(compact_count(3'400'000), "3.4M");
  EXPECT_EQ(compact_count(18'446'744'073'709'551'615ULL), "18E");
  EXPECT_EQ(compact_ns(850), "850ns");
  EXPECT_EQ(compact_ns(1234), "1.23\xc2\xb5s");
  EXPECT_EQ(compact_ns(12'345), "12.3\xc2\xb5s");
  EXPECT_EQ(compact_ns(123'456), "123\xc2\xb5s");
  EXPECT_EQ(compact_ns(999'999), "1.00ms");
  EXPECT_EQ(compact_ns(1'234'567), "1.23ms");
  EXPECT_EQ(compact_ns(-45'600), "-45.6\xc2\xb5s");
  EXPECT_EQ(compact_ns(3'600'000'000'000), "3600s");
  EXPECT_EQ(display_width("12.3\xc2\xb5s"), 6u);
}

TEST(LiveScreenFormat, LongNamesAreShortenedInTheMiddleMessagesAtTheEnd) {
  EXPECT_EQ(shorten_middle("short", 10), "short");
  EXPECT_EQ(shorten_middle("axis_tracking_error_filtered", 11), "axis_\xe2\x80\xa6tered");
  EXPECT_EQ(display_width(shorten_middle("axis_tracking_error_filtered", 11)), 11u);
  EXPECT_EQ(shorten_end("a message that goes on", 10), "a message\xe2\x80\xa6");
  EXPECT_EQ(shorten_end("\xc2\xb5\xc2\xb5\xc2\xb5", 2), "\xc2\xb5\xe2\x80\xa6") << "never cuts a code point";
}

class FourAxisScreen : public ::testing::Test {
 protected:
  void SetUp() override {
    auto r = load_project(kSrc + "/projects/four_axis_table/sync.yaml", LoadOptions{});
    ASSERT_TRUE(r.ok());
    program = std::move(r.program);
    VirtualClock clock(*program);
    clock.run_until(500'000'000);  // statistics and watched values that are not all zero
  }
  std::unique_ptr<Program> program;
  std::ostringstream terminal;
};

TEST_F(FourAxisScreen, FitsEightyColumnsWithEventsAndAFailedReloadKept) {
  LiveScreen screen(terminal, false);
  for (int i = 0; i < 20; ++i)
    screen.add_event(fmt::format("[{}.000000s] event number {} block-fault fast/an_instance_with_a_long_name: a "
                                 "message far longer than the screen is wide, as some are", i, i));
  screen.set_reload_result(false, "2 errors in projects/four_axis_table/a/very/long/path/to/the/project/sync.yaml",
                           {"sync.yaml:12:21: unknown block type 'NOPE'", "sync.yaml:14:10: unknown block instance 'y'"});
  LiveView v = screen.view(*program, 12345.6, nullptr, nullptr);
  v.tasks[0].stats.scans = 18'446'744'073'709'551'615ULL;  // the widest numbers there are
  v.tasks[0].stats.exec.mean = 987'654'321.0;
  v.tasks[0].stats.jitter.max = -123'456;
  v.tasks[0].state = "HUNG";
  v.modbus_endpoint = "127.0.0.1:5020";
  v.modbus.requests = 123'456'789;
  v.modbus.by_exception[2] = 12;
  v.modbus.by_exception[4] = 3;
  const std::string text = render_live_screen(v, 80);
  expect_fits(text, 80);
  EXPECT_TRUE(has(text, "four_axis_table_sync 1.0.0")) << text;
  EXPECT_TRUE(has(text, "RELOAD FAILED: ")) << text;
  EXPECT_TRUE(has(text, "  sync.yaml:12:21: unknown block type 'NOPE'")) << text;
  for (const auto& t : program->tasks) EXPECT_TRUE(has(text, "  " + t->config().name)) << text;
  for (const auto& w : program->watch) EXPECT_TRUE(has(text, "  " + w)) << text;
  EXPECT_TRUE(has(text, "event number 19 ")) << "the most recent event\n" << text;
  EXPECT_TRUE(has(text, "reload failed: 2 errors")) << "the reload is an event too\n" << text;
  EXPECT_FALSE(has(text, "event number 12 ")) << "only the last " << LiveScreen::kEvents << " events\n" << text;
  EXPECT_TRUE(has(text, "18E")) << text;
  EXPECT_TRUE(has(text, "Modbus 127.0.0.1:5020  clients 0  requests 123M")) << text;

  // More events and frames: the failed reload stays until a reload succeeds.
  for (int i = 0; i < 30; ++i) screen.add_event("later event " + std::to_string(i));
  std::string later = render_live_screen(screen.view(*program, 13000, nullptr, nullptr), 80);
  EXPECT_TRUE(has(later, "RELOAD FAILED: ")) << later;
  EXPECT_TRUE(has(later, "unknown block type 'NOPE'")) << later;
  screen.set_reload_result(true, "sync.yaml (41 tag values carried over)");
  later = render_live_screen(screen.view(*program, 13001, nullptr, nullptr), 80);
  EXPECT_FALSE(has(later, "RELOAD FAILED")) << later;
  EXPECT_FALSE(has(later, "NOPE")) << later;
  EXPECT_TRUE(has(later, "Last reload: ")) << later;
  EXPECT_TRUE(has(later, "sync.yaml (41 tag values carried over)")) << later;
  for (int i = 0; i < 30; ++i) screen.add_event("even later " + std::to_string(i));
  later = render_live_screen(screen.view(*program, 13002, nullptr, nullptr), 80);
  EXPECT_TRUE(has(later, "Last reload: ")) << "kept until the next reload\n" << later;
  expect_fits(later, 80);
  EXPECT_TRUE(terminal.str().empty()) << "not on a terminal: nothing written";
}

TEST_F(FourAxisScreen, ShowsTheForcesAndMarksForcedWatchedTags) {
  LiveScreen screen(terminal, false);
  std::string plain = render_live_screen(screen.view(*program, 1.0, nullptr, nullptr), 80);
  EXPECT_FALSE(has(plain, "FORCED")) << plain;
  ASSERT_FALSE(program->watch.empty());
  std::string forced_name;
  for (const auto& w : program->watch)
    if (program->find_tag(w)->length == 1) {
      forced_name = w;
      break;
    }
  ASSERT_FALSE(forced_name.empty());
  const Tag& t = *program->find_tag(forced_name);
  auto res = program->force(forced_name, t.type == IecType::BOOL ? "TRUE" : "1");
  ASSERT_TRUE(res.ok) << res.error;
  LiveView v = screen.view(*program, 1.0, nullptr, nullptr);
  EXPECT_EQ(v.forces, 1u);
  for (const auto& w : v.watched) EXPECT_EQ(w.forced, w.name == forced_name) << w.name;
  const std::string text = render_live_screen(v, 80);
  expect_fits(text, 80);
  EXPECT_TRUE(has(text, "FORCED: 1 element held at forced values (F: a watched tag)")) << text;
  EXPECT_TRUE(has(text, "F " + forced_name)) << text;
}

TEST_F(FourAxisScreen, TakesAndGivesBackTheAlternateScreen) {
  {
    LiveScreen screen(terminal, true);
    EXPECT_EQ(terminal.str(), "\x1b[?1049h\x1b[?25l");
    screen.draw(*program, 1.0, nullptr, nullptr);
    EXPECT_TRUE(has(terminal.str(), "four_axis_table_sync")) << terminal.str();
  }  // an error unwinding out of cmd_run leaves the same way
  EXPECT_TRUE(terminal.str().ends_with("\x1b[?25h\x1b[?1049l")) << terminal.str();
}

// `syncplc run` on a pseudo-terminal: everything it wrote.
struct PtyRun {
  pid_t pid = -1;
  int fd = -1;
  std::string out;
  // `realtime` false: at normal priority (a scan that never ends; see
  // drop_realtime_priority).
  void start(const std::vector<std::string>& args, bool realtime = true) {
    pid = forkpty(&fd, nullptr, nullptr, nullptr);
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      if (!realtime) testing::drop_realtime_priority();
      std::vector<char*> argv{const_cast<char*>(SYNCPLC_BINARY), const_cast<char*>("run")};
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(SYNCPLC_BINARY, argv.data());
      _exit(127);
    }
  }
  // Reads until `text` has appeared (false: the child closed the terminal,
  // or a minute passed without it: a guard against a hang only).
  bool read_until(const std::string& text) {
    char buf[4096];
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (out.find(text) == std::string::npos) {
      pollfd p{fd, POLLIN, 0};
      if (std::chrono::steady_clock::now() > until || poll(&p, 1, 100) < 0) return false;
      if (!(p.revents & (POLLIN | POLLHUP))) continue;
      const ssize_t n = read(fd, buf, sizeof buf);
      if (n <= 0) return false;
      out.append(buf, static_cast<std::size_t>(n));
    }
    return true;
  }
  int finish() {
    read_until("\x01never\x01");  // to the end (EOF)
    int status = 0;
    for (int i = 0; i < 6000 && waitpid(pid, &status, WNOHANG) == 0; ++i)  // a minute: a hang guard
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (kill(pid, 0) == 0) {  // the test failed: leave nothing running
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
    }
    close(fd);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
};

TEST(LiveScreenRun, TheAlternateScreenIsGivenBackAtSigterm) {
  std::string path = testing::write_temp_file("screen.yaml", "tasks: [{name: t, period: 1ms}]\n");
  PtyRun r;
  r.start({path});
  ASSERT_TRUE(r.read_until("Ctrl-C stops")) << r.out;
  EXPECT_EQ(r.out.find("\x1b[?1049h"), 0u) << "the alternate screen first";
  kill(r.pid, SIGTERM);
  EXPECT_EQ(r.finish(), 0) << r.out;
  const auto back = r.out.find("\x1b[?1049l");
  ASSERT_NE(back, std::string::npos) << r.out;
  EXPECT_GT(r.out.find("Statistics (real time)", back), back) << "the statistics on the normal screen";
}

TEST(LiveScreenRun, TheAlternateScreenIsGivenBackWhenAHungScanForcesTheExit) {
  std::string path = testing::write_temp_file("screen_hang.yaml", R"(tasks:
  - {name: stuck, period: 10ms, watchdog: {time: 20ms, action: stop}}
blocks: [{name: b, type: BURN, inputs: {EXEC: 1h}}]
)");
  PtyRun r;
  r.start({path, "--duration", "5s"}, false);
  EXPECT_EQ(r.finish(), 4) << r.out;
  const auto back = r.out.find("\x1b[?1049l");
  ASSERT_NE(back, std::string::npos) << r.out;
  EXPECT_GT(r.out.find("scan-hung", back), back) << "the screen's events kept on the normal screen\n" << r.out;
}

TEST(LiveScreenRun, CtrlZGivesTheShellItsScreenBackUntilTheRunContinues) {
#if defined(__SANITIZE_THREAD__)
  // ThreadSanitizer defers signals to its own points in the program: the
  // SIGTSTP the run re-raises after giving the screen back never stops it
  // there (the test would wait forever). The release and ASan builds run it.
  GTEST_SKIP() << "job control under ThreadSanitizer";
#endif
  // As a shell runs a job: the terminal's process in a process group of its
  // own, whose parent (this test) is in the same session — so SIGTSTP stops it.
  std::string path = testing::write_temp_file("screen_tstp.yaml", "tasks: [{name: t, period: 1ms}]\n");
  int master = -1, slave = -1;
  ASSERT_EQ(openpty(&master, &slave, nullptr, nullptr, nullptr), 0);
  PtyRun r;
  r.fd = master;
  r.pid = fork();
  ASSERT_GE(r.pid, 0);
  if (r.pid == 0) {
    setpgid(0, 0);
    for (int f : {0, 1, 2}) dup2(slave, f);
    execl(SYNCPLC_BINARY, SYNCPLC_BINARY, "run", path.c_str(), "--duration", "20s", static_cast<char*>(nullptr));
    _exit(127);
  }
  close(slave);
  ASSERT_TRUE(r.read_until("Ctrl-C stops")) << r.out;
  const std::size_t before = r.out.size();
  kill(r.pid, SIGTSTP);
  int status = 0;
  ASSERT_EQ(waitpid(r.pid, &status, WUNTRACED), r.pid);
  EXPECT_TRUE(WIFSTOPPED(status));
  ASSERT_TRUE(r.read_until("\x1b[?1049l")) << "the shell's screen while stopped";
  EXPECT_GT(r.out.find("\x1b[?1049l", before), before);
  const std::size_t stopped = r.out.size();
  kill(r.pid, SIGCONT);
  ASSERT_TRUE(r.read_until("\x1b[?1049h\x1b[?25l\x1b[H")) << r.out;  // taken again, then a frame
  EXPECT_GT(r.out.find("\x1b[?1049h", stopped), stopped);
  kill(r.pid, SIGTERM);
  EXPECT_EQ(r.finish(), 0) << r.out;
  EXPECT_GT(r.out.rfind("\x1b[?1049l"), r.out.rfind("Ctrl-C stops")) << "given back at the end";
}

}  // namespace
}  // namespace syncplc::cli
