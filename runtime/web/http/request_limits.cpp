#include "runtime/web/http/request_limits.hpp"

#include <boost/asio/buffer.hpp>
#include <boost/beast/http/error.hpp>
#include <boost/beast/http/parser.hpp>
#include <boost/beast/http/string_body.hpp>

#include <charconv>
#include <iterator>

namespace syncplc::web::http {
namespace bhttp = boost::beast::http;

namespace {

bool is_upload(std::string_view target) {
  const std::string_view path = target.substr(0, target.find('?'));
  return path == "/api/v1/projects/check" || path == "/api/v1/projects/load";
}

std::string trimmed(std::string_view v) {
  while (!v.empty() && (v.front() == ' ' || v.front() == '\t')) v.remove_prefix(1);
  while (!v.empty() && (v.back() == ' ' || v.back() == '\t')) v.remove_suffix(1);
  return std::string(v);
}

}  // namespace

Refusal refusal_for(const boost::beast::error_code& ec, std::string_view buffered) {
  if (ec == bhttp::error::header_limit) {
    // No line end in what came: the request line alone passed the limit.
    if (buffered.find('\n') == std::string_view::npos)
      return {414, "the request line is longer than this PLC accepts"};
    return {431, "the request's header block is larger than this PLC accepts"};
  }
  if (ec == bhttp::error::buffer_overflow) return {431, "the request's header block is larger than this PLC accepts"};
  if (ec == bhttp::error::body_limit) return {413, "the request body is larger than this PLC accepts"};
  if (ec == bhttp::error::bad_content_length) return {400, "Content-Length must be one decimal number"};
  if (ec == bhttp::error::multiple_content_length) return {400, "the request has more than one Content-Length"};
  if (ec == bhttp::error::bad_transfer_encoding)
    return {400, "Transfer-Encoding: only one 'chunked', and never beside Content-Length"};
  if (ec.category() == bhttp::make_error_code(bhttp::error::bad_method).category() &&
      ec != bhttp::error::end_of_stream && ec != bhttp::error::partial_message)
    return {400, "malformed HTTP request (" + ec.message() + ")"};
  return {};  // the client left, a timeout cut it, or the server stops: nobody to answer
}

Refusal check_head(const RequestHead& head, const Limits& limits, std::size_t* body_limit) {
  const std::string_view target(head.target().data(), head.target().size());
  if (target.size() > limits.max_target)
    return {414, "the request target is " + std::to_string(target.size()) + " bytes; at most " +
                     std::to_string(limits.max_target) + " are taken"};
  if (target.empty() || target.front() != '/') return {400, "the request target must be a path starting with /"};
  std::size_t fields = 0, hosts = 0, lengths = 0, encodings = 0;
  std::string length, transfer, content_encoding;
  for (const auto& f : head) {
    ++fields;
    const std::string_view name(f.name_string().data(), f.name_string().size());
    const std::string_view value(f.value().data(), f.value().size());
    if (same_name(name, "Host")) ++hosts;
    else if (same_name(name, "Content-Length")) {
      ++lengths;
      length = trimmed(value);
    } else if (same_name(name, "Transfer-Encoding")) {
      ++encodings;
      transfer = trimmed(value);
    } else if (same_name(name, "Content-Encoding")) {
      content_encoding = trimmed(value);
    }
  }
  if (fields > limits.max_header_fields)
    return {431, "the request has " + std::to_string(fields) + " header fields; at most " +
                     std::to_string(limits.max_header_fields) + " are taken"};
  if (hosts > 1) return {400, "the request has more than one Host"};
  if (head.version() == 11 && hosts == 0) return {400, "an HTTP/1.1 request needs a Host"};
  // One length, stated once: two framings of one body are how requests are
  // smuggled past a proxy that reads the other one.
  if (lengths > 1) return {400, "the request has more than one Content-Length"};
  if (lengths == 1 && encodings > 0) return {400, "the request has both Content-Length and Transfer-Encoding"};
  if (encodings > 1 || (encodings == 1 && !same_name(transfer, "chunked")))
    return {400, "Transfer-Encoding: only 'chunked' is taken"};
  std::uint64_t n = 0;
  if (lengths == 1) {
    const auto [end, ec] = std::from_chars(length.data(), length.data() + length.size(), n);
    if (length.empty() || ec != std::errc() || end != length.data() + length.size())
      return {400, "Content-Length must be one decimal number (it was '" + length.substr(0, 40) + "')"};
  }
  // Bodies are taken as sent: a compressed one would be unbounded once inflated.
  if (!content_encoding.empty() && !same_name(content_encoding, "identity"))
    return {415, "Content-Encoding '" + content_encoding.substr(0, 40) + "' is not taken: send the body uncompressed"};
  const std::string_view method(head.method_string().data(), head.method_string().size());
  if (method != "GET" && method != "HEAD" && method != "POST" && method != "PUT" && method != "PATCH" &&
      method != "DELETE")
    return {405, "this PLC answers GET, HEAD, POST, PUT, PATCH and DELETE"};
  // A body without a stated length would run to the connection's end.
  if ((method == "POST" || method == "PUT" || method == "PATCH") && lengths == 0 && encodings == 0)
    return {411, "a " + std::string(method) + " needs Content-Length (0 for no body) or a chunked body"};
  const std::size_t most = is_upload(target) ? limits.max_upload_body : limits.max_body;
  if (n > most)
    return {413, "the request body is " + std::to_string(n) + " bytes; at most " + std::to_string(most) +
                     " are taken here"};
  *body_limit = most;
  return {};
}

std::size_t field_count(const RequestHead& head) { return static_cast<std::size_t>(std::distance(head.begin(), head.end())); }

Refusal to_request(const RequestHead& head, std::string body, std::size_t head_fields, Request* out) {
  if (field_count(head) > head_fields) return {400, "a chunked body's trailer fields are not taken"};
  const std::string_view target(head.target().data(), head.target().size());
  const std::size_t q = target.find('?');
  out->method = std::string(head.method_string());
  if (!percent_decode(target.substr(0, q), false, &out->path) || out->path.find('\0') != std::string::npos)
    return {400, "the request's path has a bad %-escape"};
  out->params.clear();
  if (q != std::string_view::npos && !parse_query(target.substr(q + 1), &out->params))
    return {400, "the request's query has a bad %-escape"};
  out->headers.clear();
  for (const auto& f : head) out->headers.emplace_back(std::string(f.name_string()), std::string(f.value()));
  out->body = std::move(body);
  return {};
}

Refusal parse_request(std::string_view bytes, const Limits& limits, Request* out, std::size_t* consumed) {
  bhttp::request_parser<bhttp::string_body> parser;
  parser.header_limit(static_cast<std::uint32_t>(limits.max_header_bytes));
  parser.body_limit(limits.max_upload_body);
  boost::beast::error_code ec;
  std::size_t used = 0;
  // Puts what is left until `done`, an error, or nothing more is taken
  // (the rest is needed first: need_more, or no error and no progress).
  auto feed = [&](auto done) {
    while (!done() && !ec && used < bytes.size()) {
      const std::size_t n = parser.put(boost::asio::buffer(bytes.data() + used, bytes.size() - used), ec);
      used += n;
      if (ec == bhttp::error::need_more) {
        ec = {};
        break;
      }
      if (n == 0) break;
    }
  };
  feed([&] { return parser.is_header_done(); });
  if (ec) return refusal_for(ec, bytes.substr(used));
  if (!parser.is_header_done()) {
    // What a socket would wait for: a header block past the limit is refused without it.
    if (bytes.size() - used > limits.max_header_bytes) return refusal_for(bhttp::error::header_limit, bytes.substr(used));
    return {0, "incomplete"};
  }
  std::size_t body_limit = 0;
  if (Refusal r = check_head(parser.get().base(), limits, &body_limit)) return r;
  const std::size_t head_fields = field_count(parser.get().base());
  parser.body_limit(body_limit);
  ec = {};
  feed([&] { return parser.is_done(); });
  if (ec) return refusal_for(ec, {});
  if (!parser.is_done()) return {0, "incomplete"};
  if (consumed) *consumed = used;
  const RequestHead& head = parser.get().base();
  return to_request(head, std::move(parser.get().body()), head_fields, out);
}

}  // namespace syncplc::web::http
