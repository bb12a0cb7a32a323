#include "runtime/web/http/message.hpp"

#include <algorithm>

namespace syncplc::web::http {
namespace {

const std::string* find_field(const Fields& fields, std::string_view name, bool exact) {
  for (const auto& [k, v] : fields)
    if (exact ? k == name : same_name(k, name)) return &v;
  return nullptr;
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

bool same_name(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    char x = a[i], y = b[i];
    if (x >= 'A' && x <= 'Z') x = static_cast<char>(x - 'A' + 'a');
    if (y >= 'A' && y <= 'Z') y = static_cast<char>(y - 'A' + 'a');
    if (x != y) return false;
  }
  return true;
}

bool percent_decode(std::string_view in, bool plus_is_space, std::string* out) {
  std::string r;
  r.reserve(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    const char c = in[i];
    if (c == '%') {
      if (i + 2 >= in.size()) return false;
      const int hi = hex_digit(in[i + 1]), lo = hex_digit(in[i + 2]);
      if (hi < 0 || lo < 0) return false;
      r.push_back(static_cast<char>(hi * 16 + lo));
      i += 2;
    } else if (c == '+' && plus_is_space) {
      r.push_back(' ');
    } else {
      r.push_back(c);
    }
  }
  *out = std::move(r);
  return true;
}

bool parse_query(std::string_view query, Fields* out) {
  std::size_t at = 0;
  while (at <= query.size()) {
    const std::size_t amp = std::min(query.find('&', at), query.size());
    const std::string_view part = query.substr(at, amp - at);
    at = amp + 1;
    if (part.empty()) continue;
    const std::size_t eq = part.find('=');
    std::string key, value;
    if (!percent_decode(part.substr(0, eq), true, &key)) return false;
    if (eq != std::string_view::npos && !percent_decode(part.substr(eq + 1), true, &value)) return false;
    out->emplace_back(std::move(key), std::move(value));
  }
  return true;
}

bool Request::has_header(std::string_view name) const { return find_field(headers, name, false) != nullptr; }

std::string Request::get_header_value(std::string_view name) const {
  const std::string* v = find_field(headers, name, false);
  return v ? *v : std::string();
}

bool Request::has_param(std::string_view name) const { return find_field(params, name, true) != nullptr; }

std::string Request::get_param_value(std::string_view name) const {
  const std::string* v = find_field(params, name, true);
  return v ? *v : std::string();
}

void Response::set_header(std::string_view name, std::string value) {
  for (auto& [k, v] : headers)
    if (same_name(k, name)) {
      v = std::move(value);
      return;
    }
  headers.emplace_back(std::string(name), std::move(value));
}

bool Response::has_header(std::string_view name) const { return find_field(headers, name, false) != nullptr; }

std::string Response::get_header_value(std::string_view name) const {
  const std::string* v = find_field(headers, name, false);
  return v ? *v : std::string();
}

void Response::set_content(std::string content, std::string_view content_type) {
  body = std::move(content);
  set_header("Content-Type", std::string(content_type));
}

void Response::set_chunked_content_provider(std::string_view content_type, ContentProvider p,
                                            ContentProviderReleaser r) {
  set_header("Content-Type", std::string(content_type));
  provider = std::move(p);
  releaser = std::move(r);
}

}  // namespace syncplc::web::http
