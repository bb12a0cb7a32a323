// libFuzzer harness on the HTTP request path: the bytes of one connection
// go through what the HTTP server runs on them (runtime/web/http: Beast's
// parser under the limits, check_head, the body, the decoding into a
// Request) and the router with the API's route patterns, request after
// pipelined request, as a connection reads them.
// Besides ASan/UBSan, it checks the bounds: a refusal is a 4xx/5xx the
// server sends, a request taken never holds more than its limits allow, and
// a request's bytes are never more than the input.
//
// Small limits (a few KiB) so the fuzzer reaches every limit's edge quickly;
// the server's own are the same code with larger numbers.
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "runtime/web/http/request_limits.hpp"
#include "runtime/web/http/router.hpp"

namespace {

using namespace syncplc::web::http;

Limits small_limits() {
  Limits l;
  l.max_target = 512;
  l.max_header_bytes = 2048;
  l.max_header_fields = 16;
  l.max_body = 1024;
  l.max_upload_body = 4096;
  return l;
}

void check(bool ok) {
  if (!ok) std::abort();
}

// The API's patterns (runtime/web/api_*.cpp); the handlers read what the
// real ones read.
Router api_router() {
  Router r;
  auto reads = [](const Request& req, Response& res) {
    std::string seen = req.get_param_value("refs") + req.get_param_value("rate") + req.get_header_value("Authorization");
    for (const auto& m : req.matches) seen += m;
    res.set_content(std::move(seen), "text/plain");
  };
  for (const char* p : {"/api/v1/status", "/api/v1/tags", R"(/api/v1/tags/([^/]+))", "/api/v1/values", "/api/v1/blocks",
                        R"(/api/v1/blocks/([^/]+))", "/api/v1/forces", "/api/v1/events", "/api/v1/trends",
                        "/api/v1/projects", "/api/v1/stream", "/api/v1/me"})
    r.Get(p, reads);
  for (const char* p : {"/api/v1/login", "/api/v1/logout", "/api/v1/forces", "/api/v1/projects/check",
                        "/api/v1/projects/load", "/api/v1/projects/reload", "/api/v1/projects/rollback"})
    r.Post(p, reads);
  r.Put(R"(/api/v1/tags/([^/]+))", reads);
  r.Delete(R"(/api/v1/forces/(.+))", reads);
  r.Delete("/api/v1/forces", reads);
  return r;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const Limits limits = small_limits();
  static const Router router = api_router();
  std::string_view bytes(reinterpret_cast<const char*>(data), size);
  while (!bytes.empty()) {
    Request req;
    std::size_t used = 0;
    const Refusal r = parse_request(bytes, limits, &req, &used);
    if (r) {
      check(r.status >= 400 && r.status < 600 && !r.message.empty());
      break;
    }
    if (used == 0) break;  // incomplete: a socket would wait for more
    check(used <= bytes.size());
    check(req.body.size() <= limits.max_upload_body);
    check(!req.path.empty() && req.path.front() == '/');
    check(req.headers.size() <= limits.max_header_fields);
    Response res;
    router.dispatch(req, res);
    bytes.remove_prefix(used);
  }
  return 0;
}
