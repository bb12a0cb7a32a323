// A distributed project in virtual time (runtime/project/system.*,
// runtime/core/system_clock.*, the dds driver's VirtualLink): the nodes of a
// system file in one process on one simulated bus, deterministic bit for
// bit; topics that do not match refused; a node that goes away seen stale
// and taken back; scan-cycle tests that address every node.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>

#include "runtime/core/system_clock.hpp"
#include "runtime/project/scan_test.hpp"
#include "runtime/project/system.hpp"

namespace syncplc {
namespace test_dds_system {

namespace fs = std::filesystem;

// Node a counts its scans (1, 2, ...) and publishes the count; node b
// subscribes to it with the loss given.
const char* kNodeA = R"(project: {name: node_a, version: 1.0.0}
tasks: [{name: main, period: 1ms}]
tags:
  - {name: count, type: LREAL}
blocks:
  - {name: inc, type: ADD, datatype: LREAL, inputs: {IN2: 1.0}}
  - {name: last, type: UNIT_DELAY}
connections:
  - last.OUT -> inc.IN1
  - inc.OUT -> last.IN
  - inc.OUT -> count
drivers:
  - name: net
    type: dds
    node: a
    publish: [{topic: count, values: VALUES}]
    bind: BIND
)";

const char* kNodeB = R"(project: {name: node_b, version: 1.0.0}
tasks: [{name: main, period: 1ms}]
tags:
  - {name: seen, type: LREAL}
  - {name: ok, type: BOOL}
  - {name: lost, type: UDINT}
  - {name: scan, type: ULINT}
  - {name: reacting, type: BOOL}
drivers:
  - name: net
    type: dds
    node: b
    inject: {loss: LOSS, seed: 3}
    subscribe: [{topic: TOPIC, values: 1, stale_after: 5, reaction: safe, safe: [-1]}]
    bind: {TOPIC: seen, TOPIC_ok: ok, TOPIC_lost: lost, TOPIC_scan: scan, TOPIC_reaction: reacting}
)";

std::string replace(std::string s, const std::string& from, const std::string& to) {
  for (auto at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size())) s.replace(at, from.size(), to);
  return s;
}

struct SystemDir {
  SystemDir() {
    dir = fs::temp_directory_path() / ("syncplc_system_" + std::to_string(::getpid()) + "_" + std::to_string(++serial()));
    fs::create_directories(dir);
  }
  ~SystemDir() { fs::remove_all(dir); }
  static int& serial() {
    static int n = 0;
    return n;
  }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  }
  // Nodes a and b as above, and the system file naming them.
  std::string two_nodes(double loss, const std::string& topic = "count", int values = 1, const std::string& seed = "5") {
    // Another count of values: published unbound (zeros), for the layout check.
    write("a.yaml", replace(replace(kNodeA, "VALUES", std::to_string(values)), "BIND",
                            values == 1 ? "{count: count}" : "{}"));
    write("b.yaml", replace(replace(kNodeB, "LOSS", std::to_string(loss)), "TOPIC", topic));
    return write("system.yaml", "system: {name: two, seed: " + seed +
                                    "}\nnodes:\n  - {name: a, project: a.yaml}\n  - {name: b, project: b.yaml}\n");
  }
  fs::path dir;
};

// Runs a loaded system scan by scan; f(ms) after every instant.
struct Rig {
  explicit Rig(const std::string& path, const LoadOptions& o = {}) : sys(load_system_or_project(path, o)) {}
  bool open(std::string* err) {
    if (!sys.ok() || !open_system(sys, err)) return false;
    for (auto& n : sys.nodes) clocks.push_back(std::make_unique<VirtualClock>(*n.loaded.program));
    std::vector<VirtualClock*> order;
    for (auto& c : clocks) order.push_back(c.get());
    clock = std::make_unique<SystemClock>(order);
    return true;
  }
  ~Rig() { close_system(sys); }
  Cell tag(std::size_t node, const std::string& name) {
    Program& p = *sys.nodes[node].loaded.program;
    std::string err;
    auto r = p.resolve(name, &err);
    EXPECT_TRUE(r) << err;
    return *clocks[node]->live_cell(*r);
  }
  double seen() { return tag(1, "seen").get<double>(); }
  LoadedSystem sys;
  std::vector<std::unique_ptr<VirtualClock>> clocks;
  std::unique_ptr<SystemClock> clock;
};

constexpr std::int64_t kMs = 1'000'000;

TEST(DdsSystem, NodesOnOneGridSeeEachOtherOneScanLate) {
  SystemDir d;
  Rig rig(d.two_nodes(0));
  std::string err;
  ASSERT_TRUE(rig.open(&err)) << err;
  EXPECT_EQ(rig.sys.nodes[1].name, "b");
  rig.clock->run_until(0, true);
  EXPECT_FALSE(rig.tag(1, "ok").get<bool>());  // nothing yet at the first instant
  for (int k = 1; k < 200; ++k) {
    rig.clock->run_until(k * kMs, true);
    // b's scan k sees a's scan k-1, whose count is k.
    ASSERT_EQ(rig.seen(), static_cast<double>(k)) << "scan " << k;
    ASSERT_TRUE(rig.tag(1, "ok").get<bool>());
    ASSERT_EQ(rig.tag(1, "scan").get<std::uint64_t>(), static_cast<std::uint64_t>(k - 1));
  }
  EXPECT_EQ(rig.tag(1, "lost").get<std::uint32_t>(), 0u);
}

// The seen values of b over `scans` scans.
std::vector<double> run_seen(const std::string& path, int scans, const LoadOptions& o = {}, std::uint32_t* lost = nullptr) {
  Rig rig(path, o);
  std::string err;
  EXPECT_TRUE(rig.open(&err)) << err;
  std::vector<double> v;
  for (int k = 0; k < scans; ++k) {
    rig.clock->run_until(k * kMs, true);
    v.push_back(rig.seen());
  }
  if (lost) *lost = rig.tag(1, "lost").get<std::uint32_t>();
  return v;
}

TEST(DdsSystem, LossIsSeededAndARunIsTheSameBitForBit) {
  SystemDir d;
  const std::string sys = d.two_nodes(0.3);
  std::uint32_t lost1 = 0, lost2 = 0, lost3 = 0;
  const auto first = run_seen(sys, 2000, {}, &lost1);
  const auto second = run_seen(sys, 2000, {}, &lost2);
  EXPECT_EQ(first, second);
  EXPECT_EQ(lost1, lost2);
  // About 30 % of 2000 samples lost (binomial: 600 +- 4.5 sigma).
  EXPECT_GT(lost1, 510u);
  EXPECT_LT(lost1, 690u);
  LoadOptions other;
  other.seed = 6;
  const auto third = run_seen(sys, 2000, other, &lost3);
  EXPECT_NE(first, third);  // another seed, another loss pattern
}

TEST(DdsSystem, TopicsThatDoNotMatchAreRefusedAtOpen) {
  SystemDir d;
  Rig rig(d.two_nodes(0, "count", 3));
  std::string err;
  ASSERT_TRUE(rig.sys.ok());
  EXPECT_FALSE(rig.open(&err));
  EXPECT_EQ(err, "node b: driver net: dds: topic count: node 'a' publishes 3 values, node 'b' takes 1 value: the nodes' projects do not match");
}

TEST(DdsSystem, ASubscriptionNobodyPublishesIsAnErrorOfTheSystem) {
  SystemDir d;
  Rig rig(d.two_nodes(0, "cuont"));
  std::string err;
  EXPECT_FALSE(rig.open(&err));
  EXPECT_EQ(err, "dds: node 'b' subscribes topic cuont, which no node of the system publishes");
}

TEST(DdsSystem, ANodeThatGoesAwayIsSeenStaleThenTakenBack) {
  SystemDir d;
  Rig rig(d.two_nodes(0));
  std::string err;
  ASSERT_TRUE(rig.open(&err)) << err;
  rig.clock->run_until(100 * kMs, true);
  EXPECT_EQ(rig.seen(), 100.0);
  // Node a's link goes (its process killed, in real time).
  rig.sys.nodes[0].loaded.program->close_drivers();
  int stale_at = -1;
  for (int k = 101; k < 120; ++k) {
    rig.clock->run_until(k * kMs, true);
    if (stale_at < 0 && !rig.tag(1, "ok").get<bool>()) stale_at = k;
  }
  // Its scan at 100 ms sent one more sample before it went, taken at 101:
  // stale after 5 more scans (stale_after 5).
  EXPECT_EQ(stale_at, 107);
  EXPECT_TRUE(rig.tag(1, "reacting").get<bool>());
  EXPECT_EQ(rig.seen(), -1.0);  // reaction safe
  // Node a comes back (restarted): a new writer, whose samples b takes at once.
  ASSERT_TRUE(rig.sys.nodes[0].loaded.program->open_drivers(&err)) << err;
  rig.clock->run_until(122 * kMs, true);
  EXPECT_TRUE(rig.tag(1, "ok").get<bool>());
  EXPECT_FALSE(rig.tag(1, "reacting").get<bool>());
  EXPECT_EQ(rig.seen(), 122.0);
  double changed = -1;
  for (const auto& [k, v] : rig.sys.nodes[1].loaded.program->drivers[0].driver->counters())
    if (k == "writers_changed") changed = v;
  EXPECT_EQ(changed, 1.0);
}

TEST(DdsSystem, SystemFileErrorsAreReportedWhereTheyAre) {
  SystemDir d;
  d.two_nodes(0);
  const std::string path = d.write("bad.yaml", R"(system: {name: x, sed: 1}
nodes:
  - {name: a, project: a.yaml}
  - {name: a, project: b.yaml}
  - {name: 1c, project: b.yaml, colour: red}
  - {name: d}
)");
  LoadedSystem s = load_system_or_project(path, {});
  std::vector<std::string> lines;
  for (const auto& e : s.diagnostics.sorted()) lines.push_back(e.text());
  const std::string f = path + ":";
  EXPECT_THAT(lines, ::testing::ElementsAre(f + "1:24: unknown key 'sed' in system (name, seed, description)",
                                            f + "4:12: duplicate node 'a'",
                                            f + "5:12: node name '1c' is not an identifier",
                                            f + "5:41: unknown key 'colour' in a node (name, project, set)",
                                            f + "6:5: node 'd' without a project"));
  // A node's own errors carry its file and the node's name.
  d.write("b.yaml", "project: {name: b}\ntasks: [{name: main, period: 1ms}]\nblocks:\n  - {name: x, type: NOPE}\n");
  LoadedSystem s2 = load_system_or_project((d.dir / "system.yaml").string(), {});
  ASSERT_FALSE(s2.ok());
  EXPECT_THAT(s2.diagnostics.sorted().front().text(), ::testing::HasSubstr("b.yaml:4:21: node b: unknown block type 'NOPE'"));
}

TEST(DdsSystem, SetsStartWithTheirNode) {
  SystemDir d;
  const std::string sys = d.two_nodes(0);
  LoadOptions o;
  ParamOverride x;
  ASSERT_TRUE(parse_override("b.net.inject.loss=0.5", x));
  o.overrides.push_back(x);
  std::uint32_t lost = 0;
  run_seen(sys, 1000, o, &lost);
  EXPECT_GT(lost, 400u);  // about 500 of 1000
  EXPECT_LT(lost, 600u);
  LoadOptions bad;
  ASSERT_TRUE(parse_override("net.inject.loss=0.5", x));
  bad.overrides.push_back(x);
  LoadedSystem s = load_system_or_project(sys, bad);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.diagnostics.sorted().front().text(),
            "command line:0:0: --set net.inject.loss: a system's --set starts with a node (a, b)");
}

TEST(DdsSystem, ScanTestsAddressEveryNode) {
  SystemDir d;
  const std::string sys = d.two_nodes(0);
  const std::string tests = d.write("tests.yaml", R"(cases:
  - name: b sees a one scan late
    steps:
      - at: 10ms
        expect: {a.count: 11, b.seen: 10, b.ok: TRUE, b.scan: 9}
      - cycle: 20
        task: b.main
        expect: {b.seen: 20}
  - name: a wrong expectation fails with its node
    steps:
      - at: 5ms
        expect: {b.seen: 1}
)");
  const ScanTestReport r = run_scan_tests(sys, tests);
  ASSERT_TRUE(r.diagnostics.empty()) << r.diagnostics.sorted().front().text();
  ASSERT_EQ(r.cases.size(), 2u);
  EXPECT_TRUE(r.cases[0].passed) << (r.cases[0].failures.empty() ? "" : r.cases[0].failures[0]);
  ASSERT_FALSE(r.cases[1].passed);
  EXPECT_THAT(r.cases[1].failures[0], ::testing::HasSubstr("b.seen is 5, expected 1"));
  const std::string bad = d.write("bad_tests.yaml", "cases:\n  - name: x\n    steps:\n      - at: 1ms\n        expect: {seen: 1}\n");
  const ScanTestReport e = run_scan_tests(sys, bad);
  ASSERT_EQ(e.diagnostics.size(), 1u);
  EXPECT_THAT(e.diagnostics.sorted()[0].text(),
              ::testing::HasSubstr("5:24: seen: a system's target starts with its node (a, b), e.g. a.tag"));
}

}  // namespace test_dds_system
}  // namespace syncplc
