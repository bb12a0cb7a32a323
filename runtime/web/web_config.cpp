#include "runtime/web/web_config.hpp"

#include <arpa/inet.h>
#include <unistd.h>

#include <charconv>

#include "runtime/core/task_cpus.hpp"

namespace syncplc::web {

bool parse_http_address(const std::string& text, WebConfig& c, std::string* error) {
  if (text == "off" || text == "none") {
    c.enabled = false;
    return true;
  }
  std::string host = c.bind, port = text;
  if (!text.empty() && text.front() == '[') {  // [::1]:8080
    const auto close = text.find(']');
    if (close == std::string::npos || close + 1 >= text.size() || text[close + 1] != ':') {
      *error = "--http '" + text + "': write an IPv6 address as [::1]:8080";
      return false;
    }
    host = text.substr(1, close - 1);
    port = text.substr(close + 2);
  } else if (const auto colon = text.rfind(':'); colon != std::string::npos) {
    host = text.substr(0, colon);
    port = text.substr(colon + 1);
  }
  int p = -1;
  const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), p);
  if (ec != std::errc() || end != port.data() + port.size() || p < 0 || p > 65535) {
    *error = "--http '" + text + "': the port must be a number 0..65535 (or 'off')";
    return false;
  }
  in6_addr a6;
  in_addr a4;
  if (inet_pton(AF_INET, host.c_str(), &a4) != 1 && inet_pton(AF_INET6, host.c_str(), &a6) != 1) {
    *error = "--http '" + text + "': '" + host + "' is not an IP address (give the address to listen on, e.g. 127.0.0.1)";
    return false;
  }
  c.enabled = true;
  c.bind = host;
  c.port = p;
  c.explicit_address = true;
  return true;
}

bool is_loopback(const std::string& address) {
  in_addr a4;
  if (inet_pton(AF_INET, address.c_str(), &a4) == 1) return (ntohl(a4.s_addr) >> 24) == 127;
  return address == "::1";
}

bool check_config(const WebConfig& c, std::string* error) {
  if (!c.enabled) return true;
  if (c.tls_cert.empty() != c.tls_key.empty()) {
    *error = "HTTPS needs both --http-cert and --http-key";
    return false;
  }
  for (const std::string* f : {&c.tls_cert, &c.tls_key})
    if (!f->empty() && access(f->c_str(), R_OK) != 0) {
      *error = "cannot read " + *f + " (HTTPS certificate or key)";
      return false;
    }
  if (!is_loopback(c.bind) && !c.tls() && !c.allow_plain_remote) {
    *error = "--http " + c.bind + ": listening beyond this machine needs HTTPS (--http-cert, --http-key); "
             "--http-insecure allows plain HTTP (passwords and tokens then cross the network readable)";
    return false;
  }
  const cpu_set_t process = process_cpus();
  for (int cpu : c.cpus)
    if (cpu < 0 || cpu >= CPU_SETSIZE || !CPU_ISSET(cpu, &process)) {
      *error = "--http-cpus: CPU " + std::to_string(cpu) + " is not one this process may use (" + cpu_list(process) + ")";
      return false;
    }
  return true;
}

bool anonymous_reads(const WebConfig& c) { return c.anonymous_read.value_or(is_loopback(c.bind)); }

}  // namespace syncplc::web
