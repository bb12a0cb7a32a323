// `syncplc events` (--since, one line per event) and the store's state on
// the live screen and in the exit message (runtime/cli/event_query.hpp,
// store_status.hpp).
#include <gtest/gtest.h>
#include <stdlib.h>
#include <time.h>

#include "runtime/cli/event_query.hpp"
#include "runtime/cli/live_screen.hpp"
#include "runtime/plc/store_status.hpp"

namespace syncplc::cli {
namespace {
using namespace plc;

constexpr std::int64_t kSecond = 1'000'000'000;

// Local time is UTC in these tests, whatever the machine says.
struct Utc {
  Utc() {
    setenv("TZ", "UTC", 1);
    tzset();
  }
};

TEST(EventsSince, ADurationCountsBackFromNow) {
  std::string err;
  EXPECT_EQ(parse_since("10m", 1000 * kSecond, &err), 400 * kSecond);
  EXPECT_EQ(parse_since("2h", 10'000 * kSecond, &err), 2800 * kSecond);
}

TEST(EventsSince, ALocalTimeInEachWrittenForm) {
  Utc utc;
  std::string err;
  const std::int64_t t = 1795600800LL * kSecond;  // 2026-11-25 10:00:00 UTC
  EXPECT_EQ(parse_since("2026-11-25T10:00:00", 0, &err), t) << err;
  EXPECT_EQ(parse_since("2026-11-25 10:00", 0, &err), t) << err;
  EXPECT_EQ(parse_since("2026-11-25", 0, &err), t - 10 * 3600 * kSecond) << err;
}

TEST(EventsSince, AnythingElseIsAnErrorThatShowsBothForms) {
  std::string err;
  EXPECT_FALSE(parse_since("yesterday", 0, &err));
  EXPECT_EQ(err, "--since yesterday: expected a time back from now (10m, 2h) or a local time (2026-11-25T10:00:00)");
  EXPECT_FALSE(parse_since("2026-11-25T10:00:00x", 0, &err));
}

TEST(EventsFormat, OneLineWithLocalTimeKindTaskScanMessageAndClient) {
  Utc utc;
  LoggedEvent e;
  e.time_ns = 1795600800LL * kSecond + 123'456'789;
  e.kind = "hmi-write";
  e.task = "main";
  e.message = "speed := 12.5";
  e.client = "127.0.0.1:40512";
  EXPECT_EQ(format_logged_event(e),
            "2026-11-25 10:00:00.123  hmi-write         main               -  speed := 12.5  client 127.0.0.1:40512");
  e.kind = "overrun";
  e.scan = 4821;
  e.client.clear();
  e.message = "scan overran its period";
  EXPECT_EQ(format_logged_event(e),
            "2026-11-25 10:00:00.123  overrun           main       scan 4821  scan overran its period");
}

TEST(EventsFormat, AMessageOfSeveralLinesContinuesIndented) {
  Utc utc;
  LoggedEvent e;
  e.time_ns = 1795600800LL * kSecond;
  e.kind = "reload-failed";
  e.message = "2 errors in the project file\na.yaml:3:1: error one\na.yaml:9:5: error two";
  EXPECT_EQ(format_logged_event(e),
            "2026-11-25 10:00:00.000  reload-failed     -                  -  2 errors in the project file\n"
            "    a.yaml:3:1: error one\n"
            "    a.yaml:9:5: error two");
}

TEST(StoreStatusLine, OkFaultOffAndReadOnlyWithTheCountsBeforeTheErrorText) {
  StoreStatus st;
  EXPECT_EQ(store_status_line(st, "/var/lib/x/plc.db"), "Store ok  plc.db");
  st.dropped = 3;
  EXPECT_EQ(store_status_line(st, "/var/lib/x/plc.db"), "Store ok  plc.db  3 events dropped");
  st.trend_lost = 12;
  EXPECT_EQ(store_status_line(st, "/var/lib/x/plc.db"), "Store ok  plc.db  3 events dropped  12 trend buckets lost");
  EXPECT_EQ(store_status_words(st).dropped, 15u) << "the registers count both as records lost";
  st.state = StoreStatus::State::Fault;
  st.pending = 37;
  st.failures = 12;
  st.error = "events: database or disk is full";
  EXPECT_EQ(store_status_line(st, "plc.db"), "Store FAULT  37 pending  12 failures  events: database or disk is full");
  st.state = StoreStatus::State::Off;
  st.error = "cannot open the database /x/plc.db: unable to open database file";
  EXPECT_EQ(store_status_line(st, "plc.db"), "Store off  cannot open the database /x/plc.db: unable to open database file");
  EXPECT_STREQ(store_state_name(st.state), "off");
  st.state = StoreStatus::State::ReadOnly;
  st.error = "its mode is 0444";
  EXPECT_EQ(store_status_line(st, "/x/plc.db"), "Store READ-ONLY  plc.db  nothing recorded: its mode is 0444");
  EXPECT_STREQ(store_state_name(st.state), "read-only") << "as /status says it";
  EXPECT_EQ(store_status_words(st).state, 3);
}

TEST(StoreStatusRegisters, WordsSaturateAndSayNoCommitYet) {
  StoreStatus st;
  modbus::StoreStatusWords w = store_status_words(st);
  EXPECT_EQ(w.state, 0);
  EXPECT_EQ(w.since_ok_s, 0xFFFF) << "no commit yet";
  st.since_ok_ns = 7'900'000'000;
  EXPECT_EQ(store_status_words(st).since_ok_s, 7) << "whole seconds";
  st.since_ok_ns = 100'000LL * 1'000'000'000;
  EXPECT_EQ(store_status_words(st).since_ok_s, 0xFFFE) << "saturates below 'none yet'";
  st.state = StoreStatus::State::Fault;
  st.pending = 10'000;
  st.dropped = 5'000'000'000ULL;
  st.failures = 12;
  w = store_status_words(st);
  EXPECT_EQ(w.state, 1);
  EXPECT_EQ(w.pending, 10'000u);
  EXPECT_EQ(w.dropped, 0xFFFFFFFFu) << "UDINT saturates";
  EXPECT_EQ(w.failures, 12u);
  st.state = StoreStatus::State::Off;
  EXPECT_EQ(store_status_words(st).state, 2);
}

TEST(StoreStatusLine, OnTheLiveScreenWithin80Columns) {
  LiveView v;
  v.project = "demo 1.0";
  StoreStatus st;
  st.state = StoreStatus::State::Fault;
  st.pending = 10'000;
  st.failures = 1234;
  st.error = "events: attempt to write a readonly database, and a long explanation that does not fit";
  v.store = store_status_line(st, "plc.db");
  const std::string text = render_live_screen(v, 80);
  EXPECT_NE(text.find("Store FAULT  10000 pending  1234 failures  events: attempt to write"), std::string::npos)
      << text;
  for (std::size_t at = 0, nl; at < text.size(); at = nl + 1) {
    nl = text.find('\n', at);
    EXPECT_LE(display_width(text.substr(at, nl - at)), 80u);
  }
}

}  // namespace
}  // namespace syncplc::cli
