// The dds driver's settings: what loads (channels, QoS, network), and every
// error at its file:line:col.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "runtime/io/dds/dds_link.hpp"
#include "runtime/io/dds/dds_settings.hpp"
#include "tests/project/loader_test_util.hpp"

namespace syncplc {
namespace {

using loadertest::has_error;

TEST(DdsSettings, ADriverLoadsWithItsChannels) {
  auto r = loadertest::load(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: state, type: "ARRAY[1..2] OF LREAL"}
  - {name: ref, type: "ARRAY[1..4] OF LREAL"}
  - {name: ref_ok, type: BOOL}
  - {name: ref_age, type: UDINT}
drivers:
  - name: net
    type: dds
    node: axis1
    domain: 7
    peers: [127.0.0.1, 10.0.0.2]
    interface: lo
    qos: {reliability: reliable, deadline: 2ms, liveliness: 10ms}
    publish:
      - {topic: axis1_state, values: 2}
    subscribe:
      - {topic: master_ref, values: 4, stale_after: 3, reaction: safe, safe: [0, 0, 0, 1]}
    bind: {axis1_state: state, master_ref: ref, master_ref_ok: ref_ok, master_ref_age: ref_age}
)");
  ASSERT_LOADS(r);
  const auto& ch = r.program->drivers[0].driver->channels();
  ASSERT_EQ(ch.size(), 10u);  // one publication, one subscription and its eight status channels
  EXPECT_EQ(ch[0].name, "axis1_state");
  EXPECT_EQ(ch[0].dir, PinDir::Out);
  EXPECT_EQ(ch[0].length, 2u);
  EXPECT_EQ(ch[1].name, "master_ref");
  EXPECT_EQ(ch[1].length, 4u);
  EXPECT_EQ(ch[2].name, "master_ref_ok");
  EXPECT_EQ(ch[2].type, IecType::BOOL);
  EXPECT_EQ(ch[7].name, "master_ref_reaction");
  EXPECT_EQ(ch[8].name, "master_ref_phase");
  EXPECT_EQ(ch[9].name, "master_ref_fresh");
  EXPECT_EQ(ch[9].type, IecType::BOOL);
  const std::string summary = r.program->drivers[0].driver->summary();
  EXPECT_NE(summary.find("node axis1, DDS domain 7, peers 127.0.0.1 10.0.0.2"), std::string::npos) << summary;
  EXPECT_NE(summary.find("subscribes master_ref (4, stale after 3 scans: safe)"), std::string::npos) << summary;
}

TEST(DdsSettings, SetGivesANodeItsPeersAsAFlowList) {
  // One node's project on several machines: each machine's peers on its command line.
  LoadOptions o;
  ParamOverride peers, bad;
  ASSERT_TRUE(parse_override("net.peers=[10.1.0.1, 10.1.0.2]", peers));
  o.overrides.push_back(peers);
  const char* project = R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: x, type: LREAL}]
drivers:
  - name: net
    type: dds
    node: a
    peers: [127.0.0.1]
    publish: [{topic: x, values: 1}]
    bind: {x: x}
)";
  auto r = loadertest::load(project, o);
  ASSERT_LOADS(r);
  EXPECT_NE(r.program->drivers[0].driver->summary().find("peers 10.1.0.1 10.1.0.2;"), std::string::npos)
      << r.program->drivers[0].driver->summary();
  ASSERT_TRUE(parse_override("net.peers=[10.1.0.1, [x]]", bad));
  LoadOptions o2;
  o2.overrides.push_back(bad);
  EXPECT_THAT(loadertest::errors(project, o2),
              ::testing::ElementsAre("command line:1:12: peers: '' is not an address or host name"));
}

TEST(DdsSettings, ErrorsAreReportedWhereTheyAre) {
  const auto e = loadertest::errors(R"(
tasks: [{name: main, period: 1ms}]
drivers:
  - name: net
    type: dds
    node: 1axis
    domain: 300
    peers: ["<x>"]
    qos: {reliability: sometimes}
    publish:
      - {topic: a, values: 65}
    subscribe:
      - {topic: b, values: 2, reaction: explode, safe: [1, 2, 3]}
      - {topic: a_ok}
)");
  EXPECT_THAT(e, has_error("p.yaml:5:11", "node must be a name"));
  EXPECT_THAT(e, has_error("p.yaml:6:13", "domain must be an integer 0..230"));
  EXPECT_THAT(e, has_error("p.yaml:7:13", "is not an address or host name"));
  EXPECT_THAT(e, has_error("p.yaml:8:24", "reliability must be one of best_effort, reliable"));
  EXPECT_THAT(e, has_error("p.yaml:10:28", "values must be an integer 1..64"));
  EXPECT_THAT(e, has_error("p.yaml:12:41", "reaction must be one of hold, safe, stop"));
  EXPECT_THAT(e, has_error("p.yaml:12:56", "safe: one value for every element, or a list of 2"));
}

TEST(DdsSettings, ChannelNamesMustNotCollideAndSomethingMustBeExchanged) {
  auto e = loadertest::errors(R"(
tasks: [{name: main, period: 1ms}]
drivers:
  - name: net
    type: dds
    node: n
    publish:
      - {topic: x_ok}
    subscribe:
      - {topic: x}
)");
  EXPECT_THAT(e, ::testing::Contains(::testing::HasSubstr("two channels would be named 'x_ok'")));
  e = loadertest::errors(R"(
tasks: [{name: main, period: 1ms}]
drivers:
  - {name: net, type: dds, node: n}
)");
  EXPECT_THAT(e, ::testing::Contains(::testing::HasSubstr("nothing to publish or subscribe to")));
}

TEST(DdsSettings, TheCycloneConfigurationTurnsMulticastOffWithPeers) {
  dds::DdsSettings s;
  s.node = "n";
  EXPECT_EQ(dds::DdsLink::cyclone_config(s).find("AllowMulticast"), std::string::npos);
  s.peers = {"127.0.0.1", "10.0.0.2"};
  s.interface = "10.0.0.1";
  const std::string x = dds::DdsLink::cyclone_config(s);
  EXPECT_NE(x.find("<AllowMulticast>false</AllowMulticast>"), std::string::npos) << x;
  EXPECT_NE(x.find("<Peer address=\"127.0.0.1\"/><Peer address=\"10.0.0.2\"/>"), std::string::npos) << x;
  EXPECT_NE(x.find("<NetworkInterface address=\"10.0.0.1\"/>"), std::string::npos) << x;
  s.interface = "veth0";
  EXPECT_NE(dds::DdsLink::cyclone_config(s).find("<NetworkInterface name=\"veth0\"/>"), std::string::npos);
}

TEST(DdsSettings, TheLayoutWordTellsTopicsAndSizesApart) {
  EXPECT_EQ(dds::layout_word("a", 2), dds::layout_word("a", 2));
  EXPECT_NE(dds::layout_word("a", 2), dds::layout_word("a", 3));
  EXPECT_NE(dds::layout_word("a", 2), dds::layout_word("b", 2));
}

}  // namespace
}  // namespace syncplc
