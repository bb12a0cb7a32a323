// Seeded random numbers for simulated drivers and blocks: splitmix64, so a seed gives
// the same sequence on every platform and standard library (std::
// distributions are implementation-defined), which keeps virtual-time runs
// bit-for-bit reproducible.
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>
#include <string_view>

namespace syncplc {

// FNV-1a (64 bit) of a name: what a seed is mixed with so that each named
// thing (a driver, a topic) draws its own numbers (mix_seed, the dds
// driver's virtual link).
inline std::uint64_t fnv1a64(std::string_view s) noexcept {
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ULL;
  return h;
}

class SimRandom {
 public:
  explicit SimRandom(std::uint64_t seed = 1) noexcept : s_(seed) {}

  std::uint64_t next() noexcept {
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1).
  double uniform() noexcept { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  bool chance(double p) noexcept { return uniform() < p; }
  // Standard normal, Box-Muller.
  double gaussian() noexcept {
    if (spare_valid_) {
      spare_valid_ = false;
      return spare_;
    }
    double u1 = (static_cast<double>(next() >> 11) + 1.0) * 0x1.0p-53;  // (0, 1]
    double u2 = uniform();
    double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2 * std::numbers::pi * u2);
    spare_valid_ = true;
    return r * std::cos(2 * std::numbers::pi * u2);
  }

 private:
  std::uint64_t s_;
  bool spare_valid_ = false;
  double spare_ = 0;
};

}  // namespace syncplc
