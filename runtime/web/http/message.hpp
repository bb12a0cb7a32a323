// The HTTP server's own request and response (plain data): what the API's
// handlers (api_*.cpp) read and write, whatever library speaks HTTP on the
// socket (runtime/web/http_server.cpp: Boost.Beast). The member names are
// those the handlers were written against.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace syncplc::web::http {

using Fields = std::vector<std::pair<std::string, std::string>>;

struct Request {
  std::string method;  // "GET"
  std::string path;    // percent-decoded, without the query
  Fields params;       // the query, decoded, in order
  Fields headers;      // as received (names compared without case)
  std::string body;
  std::vector<std::string> matches;  // the route's regex: [0] the whole path, [1].. its groups
  std::string remote_addr;
  int remote_port = 0;

  bool has_header(std::string_view name) const;
  // The first field of that name; "" when there is none.
  std::string get_header_value(std::string_view name) const;
  bool has_param(std::string_view name) const;
  // The first value of that name; "" when there is none.
  std::string get_param_value(std::string_view name) const;
};

// Where a streamed answer (Server-Sent Events) goes. write() blocks until
// the bytes are sent, false when the client is gone or too slow (the write
// timeout): the provider then ends.
class DataSink {
 public:
  virtual ~DataSink() = default;
  virtual bool write(const char* data, std::size_t size) = 0;
  virtual void done() = 0;
  virtual bool is_writable() const = 0;
};

// Called until it returns false or calls sink.done(); `offset` is the bytes
// sent so far.
using ContentProvider = std::function<bool(std::size_t offset, DataSink& sink)>;
// Called once when the stream ends, true when it ended by done().
using ContentProviderReleaser = std::function<void(bool success)>;

struct Response {
  int status = 200;
  Fields headers;
  std::string body;
  // A streamed answer instead of body.
  ContentProvider provider;
  ContentProviderReleaser releaser;

  // Replaces a header of that name.
  void set_header(std::string_view name, std::string value);
  bool has_header(std::string_view name) const;
  std::string get_header_value(std::string_view name) const;
  void set_content(std::string content, std::string_view content_type);
  // The body from `provider`, sent chunked as it comes.
  void set_chunked_content_provider(std::string_view content_type, ContentProvider provider,
                                    ContentProviderReleaser releaser = {});
};

// Case-insensitive ASCII comparison, as header names are compared.
bool same_name(std::string_view a, std::string_view b);
// %XX decoding; '+' as a space when `plus_is_space` (a query). Returns false
// on a bad escape (out untouched then).
bool percent_decode(std::string_view in, bool plus_is_space, std::string* out);
// "a=1&b=x%20y" into pairs; false on a bad escape.
bool parse_query(std::string_view query, Fields* out);

}  // namespace syncplc::web::http
