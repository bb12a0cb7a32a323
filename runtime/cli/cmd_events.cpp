// syncplc events: the event log, read beside a running PLC (docs/store.md).
#include <unistd.h>

#include <chrono>
#include <iostream>
#include <thread>

#include "runtime/cli/commands.hpp"
#include "runtime/cli/event_query.hpp"
#include "runtime/plc/store_link.hpp"
#include "runtime/store/event_log.hpp"

namespace syncplc::cli {
using namespace plc;  // the PLC instance's database paths and stored versions (runtime/plc)

namespace {

// --follow looks for new rows this often: a reader's poll costs the writer nothing (WAL).
constexpr auto kFollowPoll = std::chrono::milliseconds(250);

}  // namespace

int cmd_events(const EventsOptions& o) {
  if (!o.online.url.empty() && !o.db.empty()) {
    std::cerr << "syncplc: events: give --url (a running PLC) or --db (its database), not both\n";
    return kExitInvalid;
  }
  if (o.db.empty() && api_url_given(o.online.url)) return events_through_api(o);
  EventFilter f;
  f.kinds = o.kinds;
  if (!o.since.empty()) {
    std::string err;
    f.since_ns = parse_since(o.since, store::wall_now_ns(), &err);
    if (!f.since_ns) {
      std::cerr << "syncplc: " << err << "\n";
      return kExitInvalid;
    }
  }
  const std::string path = o.db.empty() ? default_database_path() : o.db;
  std::string err;
  auto db = store::Database::open_read_only(path, &err);
  if (!db) {
    std::cerr << "syncplc: " << err << "\n";
    return kExitInvalid;
  }
  for (;;) {
    for (const auto& e : read_events(*db, f)) {
      std::cout << format_logged_event(e) << "\n";
      f.after_id = e.id;
    }
    if (!o.follow) return kExitOk;
    std::cout.flush();  // a pipe (| grep) sees each event when it comes
    std::this_thread::sleep_for(kFollowPoll);
  }
}

}  // namespace syncplc::cli
