// The HTTP server's share of the process's file descriptors: every
// connection costs one, and a flood of idle connections must never take
// those the Modbus server's clients and the modbus_client drivers need
// (docs/http-api.md, "Limits").
#pragma once

#include <cstddef>
#include <string>

namespace syncplc::web {

// Descriptors kept for everything but HTTP connections (the database,
// the Modbus server's listener, the drivers' sockets, threads' eventfds...)
// before the rest is shared.
inline constexpr std::size_t kDescriptorsReserved = 128;

// Raises RLIMIT_NOFILE's soft limit to its hard limit (Debian's soft limit
// is 1024, the hard one usually far more) and returns the soft limit then.
std::size_t raise_descriptor_limit();

// The HTTP connections this server may hold with `open_limit` descriptors:
// `wanted`, but never more than half of what is left beyond the reserve,
// so the other half stays for the Modbus server and the drivers.
std::size_t http_connection_budget(std::size_t wanted, std::size_t open_limit);

}  // namespace syncplc::web
