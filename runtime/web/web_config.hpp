// The HTTP server's settings (docs/http-api.md): where it listens, TLS,
// where the HMI's files are, and the limits that keep a hostile or broken
// client from costing the PLC anything.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace syncplc::web {

struct WebConfig {
  bool enabled = true;
  std::string bind = "127.0.0.1";
  int port = 8080;           // 0: any free port (tests)
  bool explicit_address = false;  // given with --http: a port in use is an error, not a warning
  std::string tls_cert, tls_key;  // both or neither: HTTPS
  bool allow_plain_remote = false;  // --http-insecure: plain HTTP on a non-loopback address
  std::optional<bool> anonymous_read;  // default: on for a loopback address, off otherwise
  std::string hmi_dir;       // "" : the installed copy beside the executable, else the build's hmi_web/dist (hmi_location.hpp)
  std::size_t max_streams = 64;          // live streams at once; more get 503
  // HTTP connections open at once (--http-max-connections); more are
  // answered 503 and closed. Never more than the HTTP server's share of the
  // file descriptors (runtime/web/descriptor_budget.hpp).
  std::size_t max_connections = 256;
  std::size_t max_body = 1 << 20;        // JSON requests
  std::size_t max_upload = 4 << 20;      // a project upload (all its files)
  std::size_t max_upload_files = 64;
  // --http-cpus: the CPUs of the server's threads. Empty: every CPU the
  // process may use but those tasks are pinned to (runtime/core/task_cpus.hpp).
  std::vector<int> cpus;

  bool tls() const { return !tls_cert.empty(); }
};

// "127.0.0.1:8080", "8080", "[::1]:8080", "0.0.0.0:8443", "off". False with
// `error` on anything else.
bool parse_http_address(const std::string& text, WebConfig& c, std::string* error);
bool is_loopback(const std::string& address);
// What the settings allow, checked before anything binds: TLS files both
// given and readable, plain HTTP beyond loopback only with allow_plain_remote.
bool check_config(const WebConfig& c, std::string* error);
bool anonymous_reads(const WebConfig& c);

}  // namespace syncplc::web
