// Live values (docs/http-api.md, "Live values"): subscriptions a client
// changes as its views open and close, read as Server-Sent Events from one
// stream each; and GET /stream?refs=…, the same stream for a short list in
// the URL. Each stream runs on its own worker and, at each tick, reads the
// newest published values: nothing queues for a slow client, it simply sees
// fewer ticks (coalesced), and a client that stops reading is cut by the
// write timeout without holding anyone else up. A reference that is unknown
// (or renamed by an online change) is answered for itself in `errors`; the
// stream goes on with the others.
#include <memory>
#include <vector>

#include "runtime/store/event_log.hpp"
#include "runtime/web/api.hpp"
#include "runtime/web/live_values.hpp"
#include "runtime/web/read_access.hpp"

namespace syncplc::web {
namespace {

struct StreamState {
  LiveRefs live;
  std::int64_t period_ns = 100'000'000;
  std::int64_t next_ns = 0;
  std::string token;                 // "" : an anonymous reader
  bool sees_everything = false;      // an engineer's stream: hmi: none values too (read_access.hpp)
  std::int64_t session_checked_ns = 0;
  // A subscription's stream: its id, this stream's attach number, the refs' version shown.
  std::string subscription;
  std::uint64_t attach = 0;
  std::uint64_t version = 0;
};

std::string event(const char* name, const nlohmann::json& data) {
  return std::string("event: ") + name + "\ndata: " +
         data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n\n";
}

std::string bearer(const http::Request& req) {
  const std::string auth = req.get_header_value("Authorization");
  return auth.rfind("Bearer ", 0) == 0 ? auth.substr(7) : std::string();
}

// One tick's `values` event.
std::string tick(ApiContext& c, StreamState& st) {
  std::string out;
  c.host.with_program([&](Program& p) {
    const std::uint64_t generation = c.host.program_generation();
    const auto hidden = st.sees_everything ? nullptr : c.hidden_cells.get(p, generation);
    nlohmann::json data = st.live.tick(p, generation, hidden.get());
    data["t_ns"] = store::wall_now_ns();
    out = event("values", data);
  });
  return out;
}

// The rate query parameter or body field: 1..50 updates per second.
bool rate_ok(double rate) { return rate >= 1 && rate <= 50; }

// Answers the request with a stream of `st`'s values; `released` runs when it ends.
void serve_stream(ApiContext& c, const http::Request& req, http::Response& res, std::shared_ptr<StreamState> st,
                  std::function<void()> released) {
  st->token = bearer(req);
  st->sees_everything = sees_everything(c.session(req));
  // Each stream holds a worker: beyond the limit, refuse rather than queue.
  if (c.streams.fetch_add(1) >= c.config.max_streams) {
    c.streams.fetch_sub(1);
    if (released) released();
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
        auto end_with = [&](const std::string& why) {
          const std::string e = event("error", {{"error", why}});
          sink.write(e.data(), e.size());
          sink.done();
          return true;
        };
        // A session logged out or expired ends its streams (checked once a second).
        if (!st->token.empty() && st->next_ns - st->session_checked_ns > 1'000'000'000) {
          st->session_checked_ns = st->next_ns;
          const auto session = c.session_of(st->token);
          // An engineer's stream also ends with the engineer's rights (hmi: none values).
          if ((!session && !anonymous_reads(c.config)) || (st->sees_everything && !sees_everything(session)))
            return end_with("the session has ended: log in again");
        }
        if (!st->subscription.empty()) {
          std::vector<std::string> refs;
          bool changed = false;
          if (!c.subscriptions.poll(st->subscription, st->attach, &st->version, &refs, &changed, now))
            return end_with("subscription " + st->subscription + " was deleted, or a newer stream of it took over");
          if (changed) st->live.set_refs(std::move(refs));
        }
        const std::string e = tick(c, *st);
        if (!sink.is_writable() || !sink.write(e.data(), e.size())) return false;
        c.counters.stream_events.fetch_add(1, std::memory_order_relaxed);
        return true;
      },
      [&c, released = std::move(released)](bool) {
        c.streams.fetch_sub(1);
        c.counters.streams_open.fetch_sub(1, std::memory_order_relaxed);
        if (released) released();
      });
}

// {ref: describe_ref} for the refs a request named.
nlohmann::json describe_refs(ApiContext& c, const http::Request& req, const std::vector<std::string>& refs) {
  nlohmann::json out = nlohmann::json::object();
  const bool all = sees_everything(c.session(req));
  c.host.with_program([&](Program& p) {
    const auto hidden = all ? nullptr : c.hidden_cells.get(p, c.host.program_generation());
    for (const auto& r : refs) out[r] = describe_ref(p, hidden.get(), r);
  });
  return out;
}

// A JSON array of strings from body[key] (absent: empty); false with a 400 answered.
bool string_list(const nlohmann::json& body, const char* key, std::vector<std::string>* out, http::Response& res) {
  if (!body.contains(key)) return true;
  const auto& v = body[key];
  if (!v.is_array()) {
    send_error(res, 400, std::string("'") + key + "' must be an array of references");
    return false;
  }
  for (const auto& r : v) {
    if (!r.is_string()) {
      send_error(res, 400, std::string("'") + key + "' must be an array of references (strings)");
      return false;
    }
    out->push_back(r.get<std::string>());
  }
  return true;
}

std::string stream_path(const std::string& id) { return "/api/v1/subscriptions/" + id + "/stream"; }

}  // namespace

void add_stream_routes(http::Router& s, ApiContext& c) {
  s.Get("/api/v1/stream", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    auto st = std::make_shared<StreamState>();
    std::vector<std::string> refs;
    const std::string list = req.get_param_value("refs");
    for (std::size_t at = 0; at <= list.size();) {
      const std::size_t comma = std::min(list.find(',', at), list.size());
      if (comma > at) refs.push_back(list.substr(at, comma - at));
      at = comma + 1;
    }
    if (refs.empty() || refs.size() > 256) {
      send_error(res, 400,
                 "name 1..256 values to stream: /api/v1/stream?refs=tag,instance.pin&rate=10 (more: POST /api/v1/subscriptions)");
      return;
    }
    st->live.set_refs(std::move(refs));
    double rate = 10;
    if (req.has_param("rate")) {
      try {
        rate = std::stod(req.get_param_value("rate"));
      } catch (const std::exception&) {
        rate = -1;
      }
      if (!rate_ok(rate)) {
        send_error(res, 400, "rate must be 1..50 updates per second");
        return;
      }
    }
    st->period_ns = static_cast<std::int64_t>(1e9 / rate);
    serve_stream(c, req, res, st, {});
  });

  // --- subscriptions -----------------------------------------------------------------
  s.Post("/api/v1/subscriptions", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    const auto body = c.json_body(req, res);
    if (!body) return;
    std::vector<std::string> refs;
    if (!string_list(*body, "refs", &refs, res)) return;
    double rate = 10;
    if (body->contains("rate")) {
      const auto& r = (*body)["rate"];
      if (!r.is_number() || !rate_ok(r.get<double>())) {
        send_error(res, 400, "rate must be 1..50 updates per second");
        return;
      }
      rate = r.get<double>();
    }
    std::string error;
    int status = 400;
    const auto sub = c.subscriptions.create(bearer(req), rate, refs, steady_now_ns(), &error, &status);
    if (!sub) {
      send_error(res, status, error);
      return;
    }
    send_json(res, 201, {{"id", sub->id}, {"rate", sub->rate}, {"stream", stream_path(sub->id)},
                         {"refs", describe_refs(c, req, sub->refs)}});
  });

  s.Get(R"(/api/v1/subscriptions/([0-9a-f]{1,64}))", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    const auto sub = c.subscriptions.get(req.matches[1], bearer(req));
    if (!sub) {
      send_error(res, 404, "no subscription " + std::string(req.matches[1]) + " of this session");
      return;
    }
    send_json(res, 200, {{"id", sub->id}, {"rate", sub->rate}, {"stream", stream_path(sub->id)},
                         {"refs", describe_refs(c, req, sub->refs)}});
  });

  s.Patch(R"(/api/v1/subscriptions/([0-9a-f]{1,64}))", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    const auto body = c.json_body(req, res);
    if (!body) return;
    std::vector<std::string> add, drop;
    if (!string_list(*body, "add", &add, res) || !string_list(*body, "drop", &drop, res)) return;
    const auto ch = c.subscriptions.change(req.matches[1], bearer(req), add, drop, steady_now_ns());
    if (!ch.ok) {
      send_error(res, ch.status, ch.error);
      return;
    }
    send_json(res, 200, {{"id", std::string(req.matches[1])}, {"refs", describe_refs(c, req, ch.added)},
                         {"dropped", ch.dropped}});
  });

  s.Delete(R"(/api/v1/subscriptions/([0-9a-f]{1,64}))", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    if (!c.subscriptions.remove(req.matches[1], bearer(req))) {
      send_error(res, 404, "no subscription " + std::string(req.matches[1]) + " of this session");
      return;
    }
    res.status = 204;
  });

  s.Get(R"(/api/v1/subscriptions/([0-9a-f]{1,64})/stream)", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    const std::string id = req.matches[1];
    const auto sub = c.subscriptions.get(id, bearer(req));
    if (!sub) {
      send_error(res, 404, "no subscription " + id + " of this session (create one: POST /api/v1/subscriptions)");
      return;
    }
    auto st = std::make_shared<StreamState>();
    st->period_ns = static_cast<std::int64_t>(1e9 / sub->rate);
    st->subscription = id;
    st->attach = c.subscriptions.attach(id, bearer(req), steady_now_ns());
    if (st->attach == 0) {
      send_error(res, 404, "no subscription " + id + " of this session");
      return;
    }
    const std::uint64_t attach = st->attach;
    serve_stream(c, req, res, st, [&c, id, attach] { c.subscriptions.detach(id, attach, steady_now_ns()); });
  });
}

}  // namespace syncplc::web
