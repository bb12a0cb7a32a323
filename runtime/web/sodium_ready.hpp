// libsodium initialised once per process before the first hash, random
// token or constant-time comparison (sodium_init picks the fastest code for
// the CPU and opens the random source; calling it again is harmless but not
// free).
#pragma once

#include <sodium.h>

#include <stdexcept>

namespace syncplc::web {

// Throws when libsodium cannot start (no random source): nothing that needs
// a password hash or a token may go on without it.
inline void sodium_ready() {
  static const bool ok = sodium_init() >= 0;  // thread-safe: a function's static is initialised once
  if (!ok) throw std::runtime_error("libsodium cannot be initialised (no source of random bytes?)");
}

}  // namespace syncplc::web
