// syncplc events --url: the event log of a running PLC through GET /events
// (docs/http-api.md), printed as `syncplc events` prints the database's.
// The API selects by id (since=ID) and one kind; --since TIME and several
// --kind are applied here to what it sends.
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <iostream>
#include <thread>

#include "runtime/cli/api_client.hpp"
#include "runtime/cli/commands.hpp"
#include "runtime/cli/event_query.hpp"
#include "runtime/cli/wall_time.hpp"

namespace syncplc::cli {
namespace {

// --follow asks this often: one small request, answered from the server's memory or database.
constexpr auto kApiFollowPoll = std::chrono::milliseconds(500);
// The most the API sends in one answer (docs/http-api.md).
constexpr int kMaxEvents = 10000;

volatile sig_atomic_t g_stop = 0;
void on_stop(int) { g_stop = 1; }

LoggedEvent from_json(const nlohmann::json& j) {
  LoggedEvent e;
  e.id = j.value("id", std::int64_t{0});
  e.time_ns = j.value("time_ns", std::int64_t{0});
  auto s = [&](const char* k) { return j.contains(k) && j[k].is_string() ? j[k].get<std::string>() : ""; };
  e.kind = s("kind");
  e.task = s("task");
  e.source = s("source");
  e.message = s("message");
  e.client = s("client");
  if (j.contains("scan") && j["scan"].is_number()) e.scan = j["scan"].get<std::int64_t>();
  return e;
}

}  // namespace

int events_through_api(const EventsOptions& o) {
  return run_online("events", [&] {
    std::optional<std::int64_t> since_ns;
    if (!o.since.empty()) {
      std::string err;
      since_ns = parse_since(o.since, wall_now_ns(), &err);
      if (!since_ns) throw ApiError(kExitInvalid, err);
    }
    auto api = connect_api(o.online);
    // --follow ends with Ctrl-C: taken here, so that the login is ended too.
    struct sigaction sa{};
    sa.sa_handler = on_stop;
    if (o.follow) {
      sigaction(SIGINT, &sa, nullptr);
      sigaction(SIGTERM, &sa, nullptr);
    }
    std::int64_t after = 0;
    for (;;) {
      std::string q = "/events?since=" + std::to_string(after) + "&limit=" + std::to_string(kMaxEvents);
      if (o.kinds.size() == 1) q += "&kind=" + url_encode(o.kinds[0]);
      const nlohmann::json answer = api->get(q);  // kept: the loop runs over a part of it
      for (const auto& j : answer.at("events")) {
        LoggedEvent e = from_json(j);
        after = std::max(after, e.id);
        if (since_ns && e.time_ns < *since_ns) continue;
        if (o.kinds.size() > 1 && std::find(o.kinds.begin(), o.kinds.end(), e.kind) == o.kinds.end()) continue;
        std::cout << format_logged_event(e) << "\n";
      }
      if (!o.follow) return kExitOk;
      std::cout.flush();
      for (auto slept = std::chrono::milliseconds(0); slept < kApiFollowPoll && !g_stop; slept += std::chrono::milliseconds(50))
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      if (g_stop) return kExitOk;
    }
  });
}

}  // namespace syncplc::cli
