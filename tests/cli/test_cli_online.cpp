// The online commands (status, read, write, force, unforce, watch, load,
// rollback, events --url, reload --url): their pure parts (values from the
// command line, the API URL, a project's files), then the real `syncplc`
// binary against a PLC's HTTP API (tests/cli/online_plc.hpp says which).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <thread>

#include "runtime/cli/api_client.hpp"
#include "runtime/cli/online_values.hpp"
#include "runtime/cli/project_upload.hpp"
#include "tests/cli/online_plc.hpp"
#include "tests/support/cli_runner.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using syncplc::testing::CliResult;
using syncplc::testing::OnlinePlc;
using syncplc::testing::run_cli;
using syncplc::testing::slurp;
using syncplc::testing::write_temp_file;

// The exit statuses of docs/user-guide.md.
constexpr int kOk = 0;
constexpr int kRefused = 2;
constexpr int kUnreachable = 6;

// ---- values from the command line --------------------------------------

TEST(CommandLineValue, NumbersBecomeJsonNumbers) {
  using syncplc::cli::value_from_command_line;
  EXPECT_EQ(value_from_command_line("42"), json(42));
  EXPECT_TRUE(value_from_command_line("42").is_number_integer());
  EXPECT_EQ(value_from_command_line("-7"), json(-7));
  EXPECT_EQ(value_from_command_line("2.5"), json(2.5));
  EXPECT_EQ(value_from_command_line("-0.125"), json(-0.125));
  EXPECT_EQ(value_from_command_line("1e3"), json(1000.0));
  EXPECT_EQ(value_from_command_line(".5"), json(0.5));
  // Exact beyond 2^53: sent as an integer, not rounded through a double.
  EXPECT_EQ(value_from_command_line("9007199254740993").dump(), "9007199254740993");
  EXPECT_EQ(value_from_command_line("18446744073709551615").dump(), "18446744073709551615");
}

TEST(CommandLineValue, TrueAndFalseBecomeBooleansInAnyCase) {
  using syncplc::cli::value_from_command_line;
  EXPECT_EQ(value_from_command_line("TRUE"), json(true));
  EXPECT_EQ(value_from_command_line("false"), json(false));
  EXPECT_EQ(value_from_command_line("True"), json(true));
}

TEST(CommandLineValue, IecTextGoesAsAString) {
  using syncplc::cli::value_from_command_line;
  for (const char* s : {"T#5ms", "1500 mm", "16#FF", "2#1010", "1.5m/s", "abc", "", "1e", "0x10", "nan", "inf",
                        "99999999999999999999999"})
    EXPECT_EQ(value_from_command_line(s), json(s)) << s;
}

TEST(CommandLineValue, ArrayForAWholeArray) {
  using syncplc::cli::value_from_command_line;
  EXPECT_EQ(value_from_command_line("[1, 2.5, 3]"), json::parse("[1, 2.5, 3]"));
  EXPECT_EQ(value_from_command_line("[1, 2"), json("[1, 2"));  // not JSON: the server's parser says why
}

TEST(ValueText, AsIecText) {
  using syncplc::cli::format_value;
  EXPECT_EQ(format_value(json(true)), "TRUE");
  EXPECT_EQ(format_value(json(1.5)), "1.5");
  EXPECT_EQ(format_value(json(0.1)), "0.1");
  EXPECT_EQ(format_value(json(24)), "24");
  EXPECT_EQ(format_value(json("T#1s500ms")), "T#1s500ms");
  EXPECT_EQ(format_value(json::parse("[1, false]")), "[1, FALSE]");
  EXPECT_EQ(format_value(json()), "?");
}

TEST(RefParts, TagElementAndPin) {
  using syncplc::cli::split_ref;
  EXPECT_EQ(split_ref("speed").name, "speed");
  EXPECT_EQ(split_ref("pos[2]").name, "pos");
  EXPECT_EQ(split_ref("pos[2]").instance, "");
  EXPECT_EQ(split_ref("sync.x[2]").instance, "sync");
  EXPECT_EQ(split_ref("sync.x[2]").name, "x");
}

// ---- the API's URL --------------------------------------------------------

TEST(ApiUrl, HostPortAndPrefix) {
  using syncplc::cli::parse_api_url;
  std::string err;
  auto u = parse_api_url("http://127.0.0.1:8080", &err);
  ASSERT_TRUE(u) << err;
  EXPECT_EQ(u->scheme, "http");
  EXPECT_EQ(u->host, "127.0.0.1");
  EXPECT_EQ(u->port, 8080);
  EXPECT_EQ(u->base_path, "");
  u = parse_api_url("https://plc.example/line1/", &err);
  ASSERT_TRUE(u) << err;
  EXPECT_EQ(u->port, 443);
  EXPECT_EQ(u->base_path, "/line1");
  u = parse_api_url("http://[::1]:9000", &err);
  ASSERT_TRUE(u) << err;
  EXPECT_EQ(u->host, "[::1]");
  EXPECT_EQ(u->port, 9000);
}

TEST(ApiUrl, OtherSchemesAndBadPortsAreRefused) {
  using syncplc::cli::parse_api_url;
  std::string err;
  EXPECT_FALSE(parse_api_url("ftp://host", &err));
  EXPECT_NE(err.find("expected http://HOST"), std::string::npos) << err;
  EXPECT_FALSE(parse_api_url("127.0.0.1:8080", &err));
  EXPECT_FALSE(parse_api_url("http://host:70000", &err));
  EXPECT_NE(err.find("70000"), std::string::npos) << err;
}

// ---- a project's files ------------------------------------------------------

// A folder of its own for one test's project files.
fs::path project_dir(const std::string& name) {
  const fs::path d = fs::path(write_temp_file(name + ".marker", "")).parent_path() / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void put(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

TEST(ProjectUpload, FollowsIncludesRecursivelyRelativeToEachFile) {
  const fs::path d = project_dir("upload_nested");
  put(d / "main.yaml", "project: {name: p}\ninclude: [parts/io.yaml, tasks.yaml]\n");
  put(d / "tasks.yaml", "tasks: [{name: t, period: 1ms}]\n");
  put(d / "parts/io.yaml", "include: ../common/tags.yaml\ntags: []\n");  // a single name, up and down again
  put(d / "common/tags.yaml", "include: [../tasks.yaml]\ntags: [{name: a, type: BOOL}]\n");  // already taken
  std::string err;
  auto up = syncplc::cli::collect_project((d / "main.yaml").string(), &err);
  ASSERT_TRUE(up) << err;
  EXPECT_EQ(up->main, "main.yaml");
  ASSERT_EQ(up->files.size(), 4u);
  EXPECT_EQ(up->files.at("common/tags.yaml"), "include: [../tasks.yaml]\ntags: [{name: a, type: BOOL}]\n");
  EXPECT_TRUE(up->files.count("parts/io.yaml"));
  EXPECT_TRUE(up->files.count("tasks.yaml"));
}

TEST(ProjectUpload, FileOutsideTheDirectoryIsRefusedWithItsInclude) {
  const fs::path d = project_dir("upload_outside");
  put(d / "p/main.yaml", "project: {name: p}\ninclude: [ok.yaml]\n");
  put(d / "p/ok.yaml", "tags: []\ninclude:\n  - ../../elsewhere.yaml\n");
  put(d / "elsewhere.yaml", "tags: []\n");
  std::string err;
  EXPECT_FALSE(syncplc::cli::collect_project((d / "p/main.yaml").string(), &err));
  EXPECT_NE(err.find("ok.yaml:3:5: include '../../elsewhere.yaml' is outside the project's directory"), std::string::npos)
      << err;
}

TEST(ProjectUpload, AnIncludeThatIsASymlinkToAFileOutsideIsRefused) {
  // The issue's case: `syncplc load` followed such a link and sent the file
  // it points to, which the PLC then loaded and stored.
  const fs::path d = project_dir("upload_symlink");
  put(d / "p/main.yaml", "project: {name: p}\ninclude: [secret.yaml]\n");
  put(d / "outside/secret.yaml", "tags: [{name: a, type: BOOL, description: not for the PLC}]\n");
  fs::create_symlink(d / "outside/secret.yaml", d / "p/secret.yaml");
  std::string err;
  EXPECT_FALSE(syncplc::cli::collect_project((d / "p/main.yaml").string(), &err));
  EXPECT_NE(err.find("main.yaml:2:11: include 'secret.yaml' resolves to " + fs::canonical(d / "outside/secret.yaml").string() +
                     ", outside the project's directory"),
            std::string::npos)
      << err;
  // A directory that is a link out: the same.
  put(d / "q/main.yaml", "include: [parts/io.yaml]\n");
  put(d / "outside/parts/io.yaml", "tags: []\n");
  fs::create_directory_symlink(d / "outside/parts", d / "q/parts");
  EXPECT_FALSE(syncplc::cli::collect_project((d / "q/main.yaml").string(), &err));
  EXPECT_NE(err.find("outside the project's directory"), std::string::npos) << err;
  // A link that stays inside is a file of the project like any other.
  put(d / "r/main.yaml", "include: [alias.yaml]\n");
  put(d / "r/real/tags.yaml", "tags: []\n");
  fs::create_symlink("real/tags.yaml", d / "r/alias.yaml");
  auto up = syncplc::cli::collect_project((d / "r/main.yaml").string(), &err);
  ASSERT_TRUE(up) << err;
  EXPECT_EQ(up->files.at("alias.yaml"), "tags: []\n");
}

TEST(ProjectUpload, StructuredTextSourcesGoWithTheirProject) {
  const fs::path d = project_dir("upload_sources");
  put(d / "main.yaml", "include: [parts/io.yaml]\nsources: [logic/main.st]\n");
  put(d / "parts/io.yaml", "sources: conveyor.st\ntags: []\n");  // relative to the file that lists it
  put(d / "logic/main.st", "PROGRAM Main\nEND_PROGRAM\n");
  put(d / "parts/conveyor.st", "FUNCTION_BLOCK Conveyor\nEND_FUNCTION_BLOCK\n");
  std::string err;
  auto up = syncplc::cli::collect_project((d / "main.yaml").string(), &err);
  ASSERT_TRUE(up) << err;
  ASSERT_EQ(up->files.size(), 4u);
  EXPECT_EQ(up->files.at("logic/main.st"), "PROGRAM Main\nEND_PROGRAM\n");
  EXPECT_TRUE(up->files.count("parts/conveyor.st"));
  put(d / "bad.yaml", "sources: [../x.st]\n");
  EXPECT_FALSE(syncplc::cli::collect_project((d / "bad.yaml").string(), &err));
  EXPECT_NE(err.find("bad.yaml:1:11: sources '../x.st' is outside the project's directory"), std::string::npos) << err;
}

TEST(ProjectUpload, AbsoluteIncludeInsideTheDirectoryIsNamedRelative) {
  const fs::path d = project_dir("upload_absolute");
  put(d / "main.yaml", "include: [" + (d / "sub/a.yaml").string() + "]\n");
  put(d / "sub/a.yaml", "tags: []\n");
  std::string err;
  auto up = syncplc::cli::collect_project((d / "main.yaml").string(), &err);
  ASSERT_TRUE(up) << err;
  EXPECT_TRUE(up->files.count("sub/a.yaml"));
}

TEST(ProjectUpload, MissingIncludeIsNamed) {
  const fs::path d = project_dir("upload_missing");
  put(d / "main.yaml", "project: {name: p}\ninclude: [there.yaml, nothere.yaml]\n");
  put(d / "there.yaml", "tags: []\n");
  std::string err;
  EXPECT_FALSE(syncplc::cli::collect_project((d / "main.yaml").string(), &err));
  EXPECT_NE(err.find("main.yaml:2:23: include 'nothere.yaml': cannot open file"), std::string::npos) << err;
}

TEST(ProjectUpload, BrokenYamlIsSentForThePlcToReport) {
  const fs::path d = project_dir("upload_broken");
  put(d / "main.yaml", "tasks: [\n");
  std::string err;
  auto up = syncplc::cli::collect_project((d / "main.yaml").string(), &err);
  ASSERT_TRUE(up) << err;
  EXPECT_EQ(up->files.at("main.yaml"), "tasks: [\n");
}

TEST(ProjectUpload, MissingMainFile) {
  std::string err;
  EXPECT_FALSE(syncplc::cli::collect_project("/nonexistent/main.yaml", &err));
  EXPECT_EQ(err, "/nonexistent/main.yaml: cannot open file");
}

// ---- the syncplc binary against a PLC ---------------------------------------

class OnlineCli : public ::testing::Test {
 protected:
  void SetUp() override {
    // The developer's own settings must not steer the tests.
    for (const char* v : {"SYNCPLC_URL", "SYNCPLC_USER", "SYNCPLC_PASSWORD"}) unsetenv(v);
    plc_ = std::make_unique<OnlinePlc>();
    ASSERT_FALSE(plc_->url().empty()) << "the PLC did not start:\n" << plc_->log();
  }

  // `syncplc ARGS --url URL`, anonymous.
  CliResult cli(const std::string& args) { return run_cli(args + " --url " + plc_->url()); }
  // The same, logged in as `user` with the password in SYNCPLC_PASSWORD.
  CliResult as(const std::string& user, const std::string& args) {
    setenv("SYNCPLC_PASSWORD", OnlinePlc::password(user).c_str(), 1);
    CliResult r = cli(args + " --user " + user);
    unsetenv("SYNCPLC_PASSWORD");
    return r;
  }

  // run() again until done(result) (events reach the log through the store
  // thread); the minute's guard only ends a hang.
  template <class Run, class Done>
  static CliResult until(Run run, Done done) {
    const auto guard = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    CliResult r = run();
    while (!done(r) && std::chrono::steady_clock::now() < guard) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      r = run();
    }
    return r;
  }
  template <class Done>
  CliResult cli_until(const std::string& args, Done done) {
    return until([&] { return cli(args); }, done);
  }

  std::unique_ptr<OnlinePlc> plc_;
};

TEST_F(OnlineCli, StatusPrintsTheTasks) {
  auto r = cli("status");
  ASSERT_EQ(r.rc, kOk) << r.err;
  EXPECT_NE(r.out.find("at " + plc_->url()), std::string::npos) << r.out;
  // The task table: header, then a row per task with its period and state.
  EXPECT_NE(r.out.find("task"), std::string::npos);
  EXPECT_NE(r.out.find("exec p99"), std::string::npos);
  EXPECT_NE(r.out.find("jitter p99"), std::string::npos);
  EXPECT_TRUE(std::regex_search(r.out, std::regex(std::string("\n") + OnlinePlc::kTask + " +1ms +running ")))
      << r.out;
  EXPECT_NE(r.out.find("forces"), std::string::npos);
}

TEST_F(OnlineCli, StatusJsonIsTheApisAnswer) {
  auto r = cli("status --json");
  ASSERT_EQ(r.rc, kOk) << r.err;
  const json j = json::parse(r.out);
  EXPECT_TRUE(j.contains("runtime"));
  EXPECT_TRUE(j["tasks"].is_array());
}

TEST_F(OnlineCli, ReadPrintsValueWithUnit) {
  auto r = cli(std::string("read ") + OnlinePlc::kTag + " '" + OnlinePlc::kElement + "' " + OnlinePlc::kPin);
  ASSERT_EQ(r.rc, kOk) << r.err;
  const std::string num = R"(-?[0-9.e+-]+)";
  EXPECT_TRUE(std::regex_search(r.out, std::regex(std::string("^") + OnlinePlc::kTag + " = " + num + " m/s\n")))
      << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(\npos\[2\] = )" + num + " rad\n"))) << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(\nax1\.x = )" + num + " rad\n"))) << r.out;
}

TEST_F(OnlineCli, ReadUnknownRefIsNotFound) {
  auto r = cli("read no_such_tag");
  EXPECT_EQ(r.rc, kRefused);
  EXPECT_NE(r.err.find("syncplc: read: not found (404): "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no_such_tag"), std::string::npos) << r.err;
}

TEST_F(OnlineCli, WriteWithoutLoginIsRefused) {
  auto r = cli(std::string("write ") + OnlinePlc::kTag + " 2.5");
  EXPECT_EQ(r.rc, kRefused);
  EXPECT_NE(r.err.find("syncplc: write: not logged in (401): "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("log in with --user NAME"), std::string::npos) << r.err;
}

TEST_F(OnlineCli, WriteAsOperatorIsReadBack) {
  auto r = as("operator", std::string("write ") + OnlinePlc::kTag + " 2.25");
  ASSERT_EQ(r.rc, kOk) << r.err;
  EXPECT_NE(r.out.find(std::string(OnlinePlc::kTag) + " := 2.25"), std::string::npos) << r.out;
  // Queued to the task: read back once a scan has applied it.
  const std::string want = std::string(OnlinePlc::kTag) + " = 2.25 m/s\n";
  r = cli_until(std::string("read ") + OnlinePlc::kTag, [&](const CliResult& x) { return x.out == want; });
  ASSERT_EQ(r.rc, kOk) << r.err;
  EXPECT_EQ(r.out, want);
}

TEST_F(OnlineCli, PasswordFromStdin) {
  const std::string in = write_temp_file("password.txt", OnlinePlc::password("operator") + "\n");
  const std::string out = write_temp_file("password.out", "");
  const std::string cmd = std::string(SYNCPLC_BINARY) + " write " + OnlinePlc::kTag + " 3 --user operator " +
                          "--password-stdin --url " + plc_->url() + " <" + in + " >" + out + " 2>&1";
  EXPECT_EQ(WEXITSTATUS(std::system(cmd.c_str())), kOk) << slurp(out);
}

TEST_F(OnlineCli, WrongPasswordIsRefused) {
  setenv("SYNCPLC_PASSWORD", "not-it", 1);
  auto r = cli(std::string("write ") + OnlinePlc::kTag + " 1 --user operator");
  unsetenv("SYNCPLC_PASSWORD");
  EXPECT_EQ(r.rc, kRefused);
  EXPECT_NE(r.err.find("login as operator: refused (401): "), std::string::npos) << r.err;
}

TEST_F(OnlineCli, ForceAsOperatorIsForbidden) {
  auto r = as("operator", std::string("force ") + OnlinePlc::kTag + " 1");
  EXPECT_EQ(r.rc, kRefused);
  EXPECT_NE(r.err.find("syncplc: force: forbidden (403): this needs the engineer role"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("engineer"), std::string::npos) << r.err;
}

TEST_F(OnlineCli, ForceShowsInReadAndUnforceReleases) {
  auto r = as("engineer", std::string("force ") + OnlinePlc::kPin + " 1.5");
  ASSERT_EQ(r.rc, kOk) << r.err;
  EXPECT_NE(r.out.find(std::string(OnlinePlc::kPin) + " forced to 1.5"), std::string::npos) << r.out;
  const std::string forced = std::string(OnlinePlc::kPin) + " = 1.5 rad (forced)\n";
  r = cli_until(std::string("read ") + OnlinePlc::kPin, [&](const CliResult& x) { return x.out == forced; });
  EXPECT_EQ(r.out, forced);
  r = cli("status");
  EXPECT_NE(r.out.find("1 element held at forced values"), std::string::npos) << r.out;
  r = as("engineer", std::string("unforce ") + OnlinePlc::kPin);
  ASSERT_EQ(r.rc, kOk) << r.err;
  EXPECT_EQ(r.out, std::string(OnlinePlc::kPin) + " released\n");
  r = as("engineer", std::string("unforce ") + OnlinePlc::kPin);
  EXPECT_EQ(r.rc, kRefused);
  EXPECT_NE(r.err.find("not found (404)"), std::string::npos) << r.err;
}

TEST_F(OnlineCli, UnforceAll) {
  ASSERT_EQ(as("engineer", std::string("force ") + OnlinePlc::kPin + " 1").rc, kOk);
  ASSERT_EQ(as("engineer", std::string("force ") + OnlinePlc::kTag + " 2").rc, kOk);
  auto r = as("engineer", "unforce --all");
  ASSERT_EQ(r.rc, kOk) << r.err;
  EXPECT_NE(r.out.find("released 2:"), std::string::npos) << r.out;
  r = as("engineer", "unforce --all");
  EXPECT_EQ(r.out, "nothing was forced\n");
  r = cli("unforce");
  EXPECT_EQ(r.rc, kRefused);
  EXPECT_NE(r.err.find("name one REF, or give --all"), std::string::npos) << r.err;
}

TEST_F(OnlineCli, WatchCountPrintsThatManyUpdates) {
  auto r = cli(std::string("watch ") + OnlinePlc::kTag + " " + OnlinePlc::kPin + " --rate 20 --count 3");
  ASSERT_EQ(r.rc, kOk) << r.err;
  // Not a terminal: one line per update, the time first, then each ref.
  const std::regex line(R"(\d\d:\d\d:\d\d\.\d\d\d  speed = [-0-9.e+]+ m/s  ax1\.x = [-0-9.e+]+ rad)");
  int lines = 0;
  for (auto it = std::sregex_iterator(r.out.begin(), r.out.end(), line); it != std::sregex_iterator(); ++it) ++lines;
  EXPECT_EQ(lines, 3) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 3) << r.out;
}

TEST_F(OnlineCli, WatchUnknownRefIsNotFoundBeforeStreaming) {
  auto r = cli("watch nothing_here --count 1");
  EXPECT_EQ(r.rc, kRefused);
  EXPECT_NE(r.err.find("not found (404)"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
}

TEST_F(OnlineCli, WatchEndsCleanlyOnCtrlC) {
  const std::string out = write_temp_file("watch.out", "");
  const pid_t pid = fork();
  if (pid == 0) {
    if (!std::freopen(out.c_str(), "w", stdout)) _exit(126);
    execl(SYNCPLC_BINARY, SYNCPLC_BINARY, "watch", OnlinePlc::kTag, "--url", plc_->url().c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
  auto lines = [&] {
    const std::string text = slurp(out);
    return std::count(text.begin(), text.end(), '\n');
  };
  // Two updates, however long a loaded machine takes (the guard only ends a hang).
  for (int i = 0; i < 6000 && lines() < 2; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "ended by a signal, not cleanly";
  EXPECT_EQ(WEXITSTATUS(status), kOk);
  EXPECT_GE(lines(), 2) << slurp(out);
}

TEST_F(OnlineCli, LoadCheckPrintsErrorLocations) {
  const fs::path d = project_dir("check_error");
  put(d / "line.yaml", "project: {name: line}\ninclude: [tasks.yaml]\n");
  put(d / "tasks.yaml", std::string("tasks:\n  - {name: main, period: ") + OnlinePlc::kBadPeriod + "}\n");
  auto r = as("engineer", "load --check " + (d / "line.yaml").string());
  EXPECT_EQ(r.rc, kRefused) << r.out;
  EXPECT_TRUE(std::regex_search(r.err, std::regex(R"((^|\n)tasks\.yaml:2:\d+: .*10xs)"))) << r.err;
  EXPECT_NE(r.err.find("line.yaml: 1 error"), std::string::npos) << r.err;
}

TEST_F(OnlineCli, LoadCheckOfAGoodProject) {
  const fs::path d = project_dir("check_good");
  put(d / "line.yaml", "project: {name: line}\ninclude: [tasks.yaml]\n");
  put(d / "tasks.yaml", "tasks:\n  - {name: main, period: 1ms}\n");
  auto r = as("engineer", "load --check " + (d / "line.yaml").string());
  ASSERT_EQ(r.rc, kOk) << r.err;
  EXPECT_NE(r.out.find("no errors"), std::string::npos) << r.out;
}

TEST_F(OnlineCli, LoadPrintsTheChangeReport) {
  const fs::path d = project_dir("load_good");
  put(d / "line.yaml", "project: {name: line}\ninclude: [tasks.yaml]\n");
  put(d / "tasks.yaml", "tasks:\n  - {name: main, period: 1ms}\n");
  auto r = cli("load " + (d / "line.yaml").string());
  EXPECT_EQ(r.rc, kRefused);
  EXPECT_NE(r.err.find("not logged in (401)"), std::string::npos) << r.err;
  r = as("engineer", "load " + (d / "line.yaml").string());
  ASSERT_EQ(r.rc, kOk) << r.err;
  EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(^version \d+ running: .*instances: \d+ kept, \d+ retuned, \d+ rewired, \d+ new, \d+ removed)")))
      << r.out;
}

TEST_F(OnlineCli, LoadRefusesAFileOutsideTheProjectDirectory) {
  const fs::path d = project_dir("load_outside");
  put(d / "p/line.yaml", "include: [../other.yaml]\n");
  put(d / "other.yaml", "tags: []\n");
  auto r = as("engineer", "load " + (d / "p/line.yaml").string());
  EXPECT_EQ(r.rc, kRefused);
  EXPECT_NE(r.err.find("is outside the project's directory"), std::string::npos) << r.err;
}

TEST_F(OnlineCli, RollbackAcceptedAndRefused) {
  auto r = as("engineer", "rollback 1");
  ASSERT_EQ(r.rc, kOk) << r.err;
  EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(^version \d+ running)"))) << r.out;
  // A version that is not there is not found (404), not the PLC's state (409).
  r = as("engineer", "rollback 999");
  EXPECT_EQ(r.rc, kRefused);
  EXPECT_NE(r.err.find("not found (404): rollback refused: there is no version 999 "), std::string::npos) << r.err;
}

TEST_F(OnlineCli, EventsThroughTheApi) {
  // The PLC's store thread writes its events to the log soon after they
  // happen: asked until they are there (the minute only ends a hang).
  auto r = cli_until("events", [](const CliResult& x) {
    return std::regex_search(x.out, std::regex(R"(\d{4}-\d\d-\d\d \d\d:\d\d:\d\d\.\d{3}  start )"));
  });
  ASSERT_EQ(r.rc, kOk) << r.err;
  EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(\d{4}-\d\d-\d\d \d\d:\d\d:\d\d\.\d{3}  start )"))) << r.out;
  r = cli_until("events --kind overrun", [](const CliResult& x) { return x.out.find("overrun") != std::string::npos; });
  ASSERT_EQ(r.rc, kOk) << r.err;
  EXPECT_NE(r.out.find("overrun"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("start "), std::string::npos) << r.out;
  r = cli("events --db /tmp/x.db");
  EXPECT_EQ(r.rc, kRefused);
  EXPECT_NE(r.err.find("not both"), std::string::npos) << r.err;
}

TEST_F(OnlineCli, EventsUrlFromTheEnvironment) {
  ASSERT_EQ(as("operator", std::string("write ") + OnlinePlc::kTag + " 4.5").rc, kOk);  // an hmi-write to find
  setenv("SYNCPLC_URL", plc_->url().c_str(), 1);
  auto r = until([] { return run_cli("events --kind hmi-write"); },
                 [](const CliResult& x) { return x.out.find("hmi-write") != std::string::npos; });
  unsetenv("SYNCPLC_URL");
  ASSERT_EQ(r.rc, kOk) << r.err;
  EXPECT_NE(r.out.find("hmi-write"), std::string::npos) << r.out;
}

TEST_F(OnlineCli, ReloadThroughTheApi) {
  auto r = as("engineer", "reload");
  ASSERT_EQ(r.rc, kOk) << r.err;
  EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(^version \d+ running)"))) << r.out;
  r = as("engineer", "reload some.yaml");
  EXPECT_EQ(r.rc, kRefused);
  EXPECT_NE(r.err.find("name no PROJECT"), std::string::npos) << r.err;
}

// Nothing listens at the URL: the status that says "cannot reach the PLC".
TEST(OnlineCliUnreachable, NothingListens) {
  unsetenv("SYNCPLC_URL");
  int port = 0;
  {
    syncplc::testing::TakenPort p;  // a free port, given back: nothing listens there now
    port = p.port;
  }
  const std::string url = "http://127.0.0.1:" + std::to_string(port);
  for (const char* cmd : {"status", "read speed", "watch speed --count 1"}) {
    auto r = run_cli(std::string(cmd) + " --url " + url);
    EXPECT_EQ(r.rc, kUnreachable) << cmd << ": " << r.err;
    EXPECT_NE(r.err.find("no syncplc run answers at " + url + " (is it running with its HTTP server on?)"),
              std::string::npos)
        << r.err;
  }
}

// https with a self-signed certificate: refused as untrusted (the PLC
// cannot be reached safely: status 6) until --cacert names it. The PLC is
// the same `syncplc run`, with --http-cert and --http-key.
TEST(OnlineCliTls, CacertTrustsASelfSignedServer) {
  unsetenv("SYNCPLC_URL");
  if (std::system("command -v openssl >/dev/null 2>&1") != 0) GTEST_SKIP() << "needs openssl";
  const fs::path d = project_dir("tls");
  const std::string make_cert = "cd " + d.string() +
                                " && openssl req -x509 -newkey rsa:2048 -nodes -keyout key.pem -out cert.pem -days 2 "
                                "-subj /CN=127.0.0.1 -addext subjectAltName=IP:127.0.0.1 >openssl.log 2>&1";
  ASSERT_EQ(std::system(make_cert.c_str()), 0) << slurp((d / "openssl.log").string());
  OnlinePlc plc({"--http-cert", (d / "cert.pem").string(), "--http-key", (d / "key.pem").string()}, "https");
  const std::string url = plc.url();
  ASSERT_FALSE(url.empty()) << "the PLC did not start:\n" << plc.log();
  auto r = run_cli("status --url " + url);
  EXPECT_EQ(r.rc, kUnreachable) << r.out;
  EXPECT_NE(r.err.find("certificate is not trusted (give its certificate with --cacert FILE)"), std::string::npos)
      << r.err;
  r = run_cli("status --url " + url + " --cacert " + (d / "cert.pem").string());
  EXPECT_EQ(r.rc, kOk) << r.err;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("^syncplc \\S+ at " + url))) << r.out;
}

TEST(OnlineCliUnreachable, BadUrlIsInvalidInput) {
  auto r = run_cli("status --url ftp://x");
  EXPECT_EQ(r.rc, kRefused);
  EXPECT_NE(r.err.find("expected http://HOST"), std::string::npos) << r.err;
}

}  // namespace
