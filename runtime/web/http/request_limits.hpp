// What the HTTP server takes from a client, and the checks of a request's
// head before any of its body is read (docs/http-api.md, "Limits"): every
// size and time is bounded, so no client can make the PLC hold more than
// these bounds allow, whatever it sends or how slowly.
#pragma once

#include <boost/beast/core/error.hpp>
#include <boost/beast/http/fields.hpp>
#include <boost/beast/http/message.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "runtime/web/http/message.hpp"

namespace syncplc::web::http {

struct Limits {
  std::size_t max_target = 8 * 1024;         // the request target (path and query): 414
  std::size_t max_header_bytes = 32 * 1024;  // request line and header fields: 431 (414 for a line alone)
  std::size_t max_header_fields = 100;       // 431
  std::size_t max_body = 1 << 20;            // a JSON request: 413
  std::size_t max_upload_body = (4 << 20) + 64 * 1024;  // a project upload (check, load)
  std::int64_t header_timeout_ms = 10'000;   // the whole header block, from the connection's last answer
  std::int64_t body_timeout_ms = 30'000;     // the whole body
  std::int64_t write_timeout_ms = 5'000;     // each write (an answer, a stream's event)
  std::size_t max_requests_per_connection = 100;
};

// A request refused before it reaches a handler: the status and why.
struct Refusal {
  int status = 0;  // 0: nothing refused
  std::string message;
  explicit operator bool() const { return status != 0; }
};

using RequestHead = boost::beast::http::request_header<>;

// The parser's error while reading a head or a body as an answer. status 0
// for a client gone or cut by a timeout (nothing is answered then).
// `buffered`: the bytes read but not parsed (tells a request line too long
// from a header block too long).
Refusal refusal_for(const boost::beast::error_code& ec, std::string_view buffered);

// A parsed head checked against the limits and this server's rules: one
// Host, at most one Content-Length, no Transfer-Encoding but chunked, no
// Content-Encoding but identity, a known method, an origin-form target.
// `body_limit` is set to the most this request's body may be.
Refusal check_head(const RequestHead& head, const Limits& limits, std::size_t* body_limit);

// The head's fields: counted when the head is read, so that fields a
// chunked body's trailer adds afterwards are told apart.
std::size_t field_count(const RequestHead& head);

// The head (checked) and the body into a Request (path decoded, query
// parsed); a refusal for a bad percent escape, or for trailer fields (more
// than `head_fields`): they would bypass the head's checks and limits.
Refusal to_request(const RequestHead& head, std::string body, std::size_t head_fields, Request* out);

// The whole path a request takes on its way in, over bytes in memory: the
// parser with the limits, check_head, the body, to_request. Used by the
// fuzzer and the tests; the server runs the same steps on a socket.
// `consumed` is the bytes one request took (a pipelined next one follows).
Refusal parse_request(std::string_view bytes, const Limits& limits, Request* out, std::size_t* consumed = nullptr);

}  // namespace syncplc::web::http
