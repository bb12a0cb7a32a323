// The modbus_client driver's settings: what loads, and every error at its
// file:line:col.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "runtime/io/modbus_client/modbus_client.hpp"
#include "tests/project/loader_test_util.hpp"

namespace syncplc {
namespace {

using loadertest::has_error;

TEST(ModbusClientConfig, AWholeDriverLoadsWithItsChannels) {
  auto r = loadertest::load(R"(
tasks: [{name: main, period: 10ms}]
tags:
  - {name: temps, type: "ARRAY[1..2] OF LREAL", unit: K}
  - {name: temps_ok, type: BOOL}
  - {name: age, type: LREAL, unit: ms}
  - {name: speed, type: REAL}
  - {name: pump, type: BOOL, safe: FALSE}
drivers:
  - name: io
    type: modbus_client
    devices:
      - {name: plc2, host: 127.0.0.1, port: 5020, unit: 3, response_timeout: 50ms, word_order: low_first}
      - {name: valve, port: 5021, reaction: stop, stale_after: 200ms}
    groups:
      - {name: t, device: plc2, function: read_input_registers, address: 10, count: 2, type: INT, scale: 0.1,
         offset: -40, unit: K, every: 100ms, reaction: safe, safe: [20, 21]}
      - {name: s, device: plc2, function: 16, address: 0, type: REAL, on_change: true}
      - {name: p, device: valve, function: 5, address: 7}
      - {name: x, device: valve, function: 23, address: 0, count: 4, write_address: 10, write_count: 2, type: UDINT}
    bind: {t: temps, t_ok: temps_ok, t_age: age, s: speed, p: pump}
)");
  ASSERT_LOADS(r);
  auto& d = static_cast<ModbusClientDriver&>(*r.program->drivers[0].driver);
  const auto& c = d.config();
  ASSERT_EQ(c.devices.size(), 2u);
  EXPECT_EQ(c.devices[0].unit, 3);
  EXPECT_EQ(c.devices[0].response_timeout_ns, 50'000'000);
  EXPECT_EQ(c.devices[1].host, "127.0.0.1");
  ASSERT_EQ(c.groups.size(), 4u);
  EXPECT_EQ(c.groups[0].format.order, WordOrder::LowFirst);  // the device's
  EXPECT_EQ(c.groups[0].format.channel(), IecType::LREAL);
  EXPECT_EQ(c.groups[0].interval_ns, 100'000'000);
  EXPECT_EQ(c.groups[0].safe[1].get<double>(), 21.0);
  EXPECT_EQ(c.groups[1].interval_ns, 10'000'000);  // every scan: the task's period
  EXPECT_TRUE(c.groups[1].on_change);
  EXPECT_EQ(c.groups[2].reaction, StaleReaction::Stop);  // the device's
  EXPECT_EQ(c.groups[2].stale_after_ns, 200'000'000);
  EXPECT_EQ(c.groups[3].write_count, 2u);
  EXPECT_EQ(d.channels()[static_cast<std::size_t>(d.channel_index("t"))].dir, PinDir::In);
  EXPECT_EQ(d.channels()[static_cast<std::size_t>(d.channel_index("s"))].dir, PinDir::Out);
  EXPECT_EQ(d.channels()[static_cast<std::size_t>(d.channel_index("x_write"))].length, 2u);
  EXPECT_EQ(d.channels()[static_cast<std::size_t>(d.channel_index("x"))].type, IecType::UDINT);
  EXPECT_EQ(d.channels()[static_cast<std::size_t>(d.channel_index("p_error"))].type, IecType::UINT);
  EXPECT_EQ(d.channels()[static_cast<std::size_t>(d.channel_index("x_reconnects"))].type, IecType::UDINT);
  EXPECT_NE(d.summary().find("plc2 127.0.0.1:5020 unit 3"), std::string::npos);
}

TEST(ModbusClientConfig, EveryMistakeIsReportedWhereItIs) {
  auto e = loadertest::errors(R"(
tasks: [{name: main, period: 10ms}]
drivers:
  - name: io
    type: modbus_client
    devices:
      - {name: a, port: 70000, unit: 256, response_timeout: 0s, reconnect_min: 2s, reconnect_max: 1s, color: red}
      - {name: a, host: "bad host!", port: 502, reaction: explode}
      - {port: 503}
    groups:
      - {name: g1, function: 3, address: 0}
      - {name: g2, device: b, function: 3, address: 0}
      - {name: g3, device: a, function: 9, address: 0}
      - {name: g4, device: a, function: 3, address: 0, count: 126}
      - {name: g5, device: a, function: 1, address: 0, type: INT}
      - {name: g6, device: a, function: 3, address: 65535, count: 1, type: DINT}
      - {name: g7, device: a, function: 6, address: 0, type: DINT}
      - {name: g8, device: a, function: 3, address: 0, on_change: true}
      - {name: g9, device: a, function: 16, address: 0, reaction: safe}
      - {name: g10, device: a, function: 3, address: 0, safe: 1}
      - {name: g11, device: a, function: 3, address: 0, count: 2, reaction: safe, safe: [1, 2, 3]}
      - {name: g12, device: a, function: 3, address: 0, every: fast}
      - {name: g13, device: a, function: 3, address: 0, write_address: 4}
      - {name: g14, device: a, function: 23, address: 0}
      - {name: g15, device: a, function: 1, address: 0, scale: 2}
      - {name: g16, device: a, function: 3, type: BOOL}
      - {name: g17, device: a, function: 3, address: 0}
      - {name: g17, device: a, function: 1, address: 0}
      - {name: "9x", device: a, function: 3, address: 0}
)");
  EXPECT_THAT(e, has_error("p.yaml:6:25", "port must be an integer 1..65535"));
  EXPECT_THAT(e, has_error("p.yaml:6:38", "unit must be an integer 0..255"));
  EXPECT_THAT(e, has_error("p.yaml:6:61", "response_timeout 0s is outside 1ms .. 1m"));
  EXPECT_THAT(e, has_error("p.yaml:6:99", "reconnect_max must be at least reconnect_min (2s)"));
  EXPECT_THAT(e, has_error("p.yaml:6:110", "unknown key 'color' in a device (name, host, port"));
  EXPECT_THAT(e, has_error("p.yaml:7:16", "duplicate device 'a'"));
  EXPECT_THAT(e, has_error("p.yaml:7:25", "host: expected an IPv4 address or a host name"));
  EXPECT_THAT(e, has_error("p.yaml:7:59", "reaction must be one of hold, safe, stop, not 'explode'"));
  EXPECT_THAT(e, has_error("p.yaml:8:9", "a device needs a name"));
  EXPECT_THAT(e, has_error("p.yaml:10:9", "request group g1 needs device: (the driver has 3 devices)"));
  EXPECT_THAT(e, has_error("p.yaml:11:28", "unknown device 'b'"));
  EXPECT_THAT(e, has_error("p.yaml:12:41", "function: '9' is not 1, 2, 3, 4, 5, 6, 15, 16 or 23"));
  EXPECT_THAT(e, has_error("p.yaml:13:63", "count 126 takes 126 registers; function 3 carries at most 125"));
  EXPECT_THAT(e, has_error("p.yaml:14:62", "type: coils and discrete inputs are BOOL"));
  EXPECT_THAT(e, has_error("p.yaml:15:53", "address + count runs past 65535"));
  EXPECT_THAT(e, has_error("p.yaml:16:62", "function 6 writes one 16-bit register: count 1 of a 16-bit type"));
  EXPECT_THAT(e, has_error("p.yaml:17:67", "on_change is for groups that write"));
  EXPECT_THAT(e, has_error("p.yaml:18:67", "reaction safe sets inputs"));
  EXPECT_THAT(e, has_error("p.yaml:19:63", "safe: values are used by reaction safe only (this group's reaction is hold)"));
  EXPECT_THAT(e, has_error("p.yaml:20:89", "safe: expected one value for every element or a list of 2"));
  EXPECT_THAT(e, has_error("p.yaml:21:64", "every: 'fast' is not a duration"));
  EXPECT_THAT(e, has_error("p.yaml:22:72", "write_address is for function 23 only"));
  EXPECT_THAT(e, has_error("p.yaml:23:9", "function 23 needs write_address:"));
  EXPECT_THAT(e, has_error("p.yaml:24:64", "scale and offset are for register values, not BOOL"));
  EXPECT_THAT(e, has_error("p.yaml:25:9", "request group g16 needs address:"));
  EXPECT_THAT(e, has_error("p.yaml:25:51", "type: registers hold integers, bit strings and reals, not BOOL"));
  EXPECT_THAT(e, has_error("p.yaml:27:16", "request group g17: its channel names clash with another group's"));
  EXPECT_THAT(e, has_error("p.yaml:28:16", "a request group needs a name"));
  EXPECT_EQ(e.size(), 28u);
}

TEST(ModbusClientConfig, AliveEveryIsAnOnChangeGroupsLivenessCheck) {
  auto r = loadertest::load(R"(
tasks: [{name: main, period: 10ms}]
drivers:
  - name: io
    type: modbus_client
    devices: [{name: a, port: 5020}]
    groups:
      - {name: w1, function: 6, address: 0, on_change: true}
      - {name: w2, function: 6, address: 1, on_change: true, alive_every: 250ms}
      - {name: w3, function: 6, address: 2, on_change: true, alive_every: 0s}
)");
  ASSERT_LOADS(r);
  const auto& c = static_cast<ModbusClientDriver&>(*r.program->drivers[0].driver).config();
  EXPECT_EQ(c.groups[0].alive_every_ns, 1'000'000'000);  // the default
  EXPECT_EQ(c.groups[1].alive_every_ns, 250'000'000);
  EXPECT_EQ(c.groups[2].alive_every_ns, 0);  // never
  auto e = loadertest::errors(R"(
tasks: [{name: main, period: 10ms}]
drivers:
  - name: io
    type: modbus_client
    devices: [{name: a, port: 5020}]
    groups:
      - {name: w1, function: 6, address: 0, alive_every: 1s}
      - {name: w2, function: 6, address: 1, on_change: true, alive_every: 2h}
)");
  EXPECT_THAT(e, has_error("p.yaml:7:58", "alive_every is for on_change groups"));
  EXPECT_THAT(e, has_error("p.yaml:8:75", "alive_every 2h is outside 0ms .. 1h"));
  EXPECT_EQ(e.size(), 2u);
}

// A negative duration is an error where it is written, never the default
// taken silently (on main "-5ms" parsed as "no value" and passed every check).
TEST(ModbusClientConfig, NegativeDurationsAreErrorsWhereTheyAre) {
  auto e = loadertest::errors(R"(
tasks: [{name: main, period: 10ms}]
drivers:
  - name: io
    type: modbus_client
    devices:
      - name: a
        port: 5020
        response_timeout: -5ms
        connect_timeout: -1s
        reconnect_min: -100ms
        reconnect_max: -1s
        stale_after: -200ms
    groups:
      - name: w
        function: 6
        address: 0
        on_change: true
        every: -10ms
        alive_every: -1s
        stale_after: -1ms
)");
  EXPECT_THAT(e, has_error("p.yaml:8:27", "response_timeout -5ms is negative; it must be within 1ms .. 1m"));
  EXPECT_THAT(e, has_error("p.yaml:9:26", "connect_timeout -1s is negative"));
  EXPECT_THAT(e, has_error("p.yaml:10:24", "reconnect_min -100ms is negative"));
  EXPECT_THAT(e, has_error("p.yaml:11:24", "reconnect_max -1s is negative"));
  EXPECT_THAT(e, has_error("p.yaml:12:22", "stale_after -200ms is negative"));
  EXPECT_THAT(e, has_error("p.yaml:18:16", "every -10ms is negative"));
  EXPECT_THAT(e, has_error("p.yaml:19:22", "alive_every -1s is negative"));
  EXPECT_THAT(e, has_error("p.yaml:20:22", "stale_after -1ms is negative"));
  EXPECT_EQ(e.size(), 8u);
}

TEST(ModbusClientConfig, AtStopIsKeepOrSafe) {
  const std::string head = R"(
tasks: [{name: main, period: 10ms}]
drivers:
  - name: io
    type: modbus_client
    devices: [{name: a, port: 5020}]
    groups: [{name: w, function: 6, address: 0}]
)";
  auto keep = loadertest::load(head.c_str());
  ASSERT_LOADS(keep);
  EXPECT_FALSE(static_cast<ModbusClientDriver&>(*keep.program->drivers[0].driver).config().safe_at_stop);  // the default
  auto safe = loadertest::load((head + "    at_stop: safe\n").c_str());
  ASSERT_LOADS(safe);
  EXPECT_TRUE(static_cast<ModbusClientDriver&>(*safe.program->drivers[0].driver).config().safe_at_stop);
  auto e = loadertest::errors((head + "    at_stop: zero\n").c_str());
  EXPECT_THAT(e, has_error("p.yaml:7:14", "at_stop must be one of keep, safe, not 'zero'"));
}

TEST(ModbusClientConfig, SetReachesADeviceOrAGroupByItsName) {
  // A launcher that starts the devices on free ports passes them in:
  // --set io.devices.d2.port=P (scripts/four_axis_network.py).
  LoadOptions o;
  o.overrides = {{"io", "devices.d2.port", "5031"}, {"io", "devices.d1.response_timeout", "20ms"},
                 {"io", "groups.g2.address", "7"}, {"io", "groups.g2.type", "DINT"}};
  const char* text = R"(
tasks: [{name: main, period: 10ms}]
drivers:
  - name: io
    type: modbus_client
    devices: [{name: d1, port: 5020}, {name: d2, port: 5021}]
    groups:
      - {name: g1, device: d1, function: 3, address: 0}
      - {name: g2, device: d2, function: 3, address: 0}
)";
  auto r = loadertest::load(text, o);
  ASSERT_LOADS(r);
  const auto& c = static_cast<ModbusClientDriver&>(*r.program->drivers[0].driver).config();
  EXPECT_EQ(c.devices[0].port, 5020);
  EXPECT_EQ(c.devices[0].response_timeout_ns, 20'000'000);
  EXPECT_EQ(c.devices[1].port, 5031);
  EXPECT_EQ(c.groups[0].address, 0);
  EXPECT_EQ(c.groups[1].address, 7);
  EXPECT_EQ(c.groups[1].format.wire, IecType::DINT) << "a group's type is a setting (a driver's own type is not)";

  LoadOptions bad;
  bad.overrides = {{"io", "devices.d3.port", "1"}, {"io", "devices.d1", "1"}, {"io", "devices.d2.port", "0"},
                   {"io", "groups.g1.name", "x"}};
  auto e = loadertest::errors(text, bad);
  EXPECT_THAT(e, ::testing::Contains("command line:0:0: --set io.devices.d3.port: devices has no item named 'd3'"));
  EXPECT_THAT(e, ::testing::Contains("command line:0:0: --set io.devices.d1: name a setting of devices item d1"));
  EXPECT_THAT(e, has_error("command line:0:0", "port"));
  EXPECT_THAT(e, ::testing::Contains("command line:0:0: --set io.groups.g1.name: an item's name cannot be overridden"));
}

// A group without address: whose count runs past 65535 is reported, never a crash.
TEST(ModbusClientConfig, AGroupWithoutAddressAndTooLongACountIsAnError) {
  auto e = loadertest::errors(R"(
tasks: [{name: main, period: 10ms}]
drivers:
  - name: io
    type: modbus_client
    devices: [{name: d1, port: 5020}]
    groups: [{name: g, device: d1, function: 3, type: DINT, count: 40000}]
)");
  EXPECT_THAT(e, has_error("p.yaml:6:14", "request group g needs address:"));
  EXPECT_THAT(e, has_error("p.yaml:6:14", "address + count runs past 65535"));
}

TEST(ModbusClientConfig, DevicesAndGroupsAreRequired) {
  auto e = loadertest::errors(R"(
tasks: [{name: main, period: 10ms}]
drivers:
  - {name: io, type: modbus_client, groups: []}
)");
  EXPECT_THAT(e, has_error("p.yaml:3:5", "devices: expected a list"));
  auto e2 = loadertest::errors(R"(
tasks: [{name: main, period: 10ms}]
drivers:
  - {name: io, type: modbus_client, devices: [{name: d, port: 502}]}
)");
  EXPECT_THAT(e2, has_error("p.yaml:3:5", "groups: expected a list"));
}

}  // namespace
}  // namespace syncplc
