// GET /stream: chosen values as Server-Sent Events (docs/http-api.md).
// Each stream runs on its own worker and, at each tick, reads the newest
// published values: nothing queues for a slow client, it simply sees fewer
// ticks (coalesced), and a client that stops reading is cut by the write
// timeout without holding anyone else up.
#include <memory>
#include <vector>

#include "runtime/store/event_log.hpp"
#include "runtime/web/api.hpp"
#include "runtime/web/program_json.hpp"
#include "runtime/web/read_access.hpp"

namespace syncplc::web {
namespace {

struct StreamState {
  std::vector<std::string> refs;
  std::int64_t period_ns = 100'000'000;
  std::int64_t next_ns = 0;
  std::string token;                 // "" : an anonymous reader
  bool sees_everything = false;      // an engineer's stream: hmi: none values too (read_access.hpp)
  std::int64_t session_checked_ns = 0;
  std::uint64_t generation = ~std::uint64_t{0};
  std::vector<std::optional<CellRef>> resolved;
};

std::string event(const char* name, const nlohmann::json& data) {
  return std::string("event: ") + name + "\ndata: " +
         data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n\n";
}

// One tick's event, or an error event (an unknown ref) that ends the stream.
std::string tick(ApiContext& c, StreamState& st, bool* end) {
  std::string out;
  c.host.with_program([&](Program& p) {
    if (st.generation != c.host.program_generation()) {
      // The program changed (online change): the refs are looked up again.
      st.generation = c.host.program_generation();
      st.resolved.clear();
      const auto hidden = st.sees_everything ? nullptr : c.hidden_cells.get(p, st.generation);
      for (const auto& ref : st.refs) {
        std::string why;
        auto r = p.resolve(ref, &why);
        if (r && hidden && hidden->hides(*r)) {
          r.reset();
          why = hidden_reason(ref);
        }
        if (!r) {
          out = event("error", {{"error", why.empty() ? "no tag or pin '" + ref + "'" : why}});
          *end = true;
          return;
        }
        st.resolved.push_back(r);
      }
    }
    const ForcedCells forced = forced_cells(p);
    nlohmann::json values = nlohmann::json::object(), flags = nlohmann::json::object();
    for (std::size_t i = 0; i < st.refs.size(); ++i) {
      const RefValue v = ref_value(p, *st.resolved[i], forced);
      if (v.value.is_null()) continue;  // a pin whose monitoring is starting
      values[st.refs[i]] = v.value;
      flags[st.refs[i]] = v.forced;
    }
    out = event("values", {{"t_ns", store::wall_now_ns()}, {"values", values}, {"forced", flags}});
  });
  return out;
}

}  // namespace

void add_stream_routes(http::Router& s, ApiContext& c) {
  s.Get("/api/v1/stream", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    auto st = std::make_shared<StreamState>();
    const std::string refs = req.get_param_value("refs");
    for (std::size_t at = 0; at <= refs.size();) {
      const std::size_t comma = std::min(refs.find(',', at), refs.size());
      if (comma > at) st->refs.push_back(refs.substr(at, comma - at));
      at = comma + 1;
    }
    if (st->refs.empty() || st->refs.size() > 256) {
      send_error(res, 400, "name 1..256 values to stream: /api/v1/stream?refs=tag,instance.pin&rate=10");
      return;
    }
    double rate = 10;
    if (req.has_param("rate")) {
      try {
        rate = std::stod(req.get_param_value("rate"));
      } catch (const std::exception&) {
        rate = -1;
      }
      if (!(rate >= 1 && rate <= 50)) {
        send_error(res, 400, "rate must be 1..50 updates per second");
        return;
      }
    }
    st->period_ns = static_cast<std::int64_t>(1e9 / rate);
    const std::string auth = req.get_header_value("Authorization");
    if (auth.rfind("Bearer ", 0) == 0) st->token = auth.substr(7);
    st->sees_everything = sees_everything(c.session(req));
    // Each stream holds a worker: beyond the limit, refuse rather than queue.
    if (c.streams.fetch_add(1) >= c.config.max_streams) {
      c.streams.fetch_sub(1);
      send_error(res, 503, "this PLC already serves " + std::to_string(c.config.max_streams) + " live streams; try again later");
      return;
    }
    c.counters.streams_open.fetch_add(1, std::memory_order_relaxed);
    res.set_header("X-Accel-Buffering", "no");
    res.set_header("Cache-Control", "no-store");
    res.set_chunked_content_provider(
        "text/event-stream",
        [&c, st](std::size_t, http::DataSink& sink) {
          const std::int64_t now = steady_now_ns();
          if (st->next_ns == 0) st->next_ns = now;  // the first event at once
          if (now < st->next_ns && !c.wait_ns(st->next_ns - now)) {
            sink.done();  // the server stops
            return true;
          }
          // The next tick one period on; ticks a slow client missed are skipped, not caught up.
          st->next_ns += st->period_ns;
          if (const std::int64_t t = steady_now_ns(); st->next_ns < t) st->next_ns = t + st->period_ns;
          // A session logged out or expired ends its streams (checked once a second).
          if (!st->token.empty() && st->next_ns - st->session_checked_ns > 1'000'000'000) {
            st->session_checked_ns = st->next_ns;
            const auto session = c.session_of(st->token);
            // An engineer's stream also ends with the engineer's rights (hmi: none values).
            if ((!session && !anonymous_reads(c.config)) || (st->sees_everything && !sees_everything(session))) {
              const std::string e = event("error", {{"error", "the session has ended: log in again"}});
              sink.write(e.data(), e.size());
              sink.done();
              return true;
            }
          }
          bool end = false;
          const std::string e = tick(c, *st, &end);
          if (!sink.is_writable() || !sink.write(e.data(), e.size())) return false;
          c.counters.stream_events.fetch_add(1, std::memory_order_relaxed);
          if (end) sink.done();
          return true;
        },
        [&c](bool) {
          c.streams.fetch_sub(1);
          c.counters.streams_open.fetch_sub(1, std::memory_order_relaxed);
        });
  });
}

}  // namespace syncplc::web
