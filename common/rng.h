#pragma once
// A counter-based random number generator. Why not <random>: the standard distributions are
// implementation-defined, and a counter-based stream lets every seed/sample draw its numbers from
// (user seed, index) alone, so results do not depend on the thread count or the platform's library.
#include <cstdint>

namespace voroudf {

/// SplitMix64 (Steele, Lea, Flood 2014), used both as a hash and as a sequential generator.
inline uint64_t SplitMix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

class Rng {
 public:
  /// A stream determined by the user's seed and a stream index (e.g. the seed number).
  Rng(uint64_t seed, uint64_t stream) : state_(SplitMix64(seed ^ SplitMix64(stream + 0x632BE59BD9B4E019ull))) {}

  uint64_t NextU64() {
    state_ += 0x9E3779B97F4A7C15ull;
    uint64_t z = state_;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>(NextU64() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  /// Uniform integer in [0, n), n > 0.
  uint64_t Below(uint64_t n) { return static_cast<uint64_t>(Uniform() * static_cast<double>(n)) % n; }

 private:
  uint64_t state_;
};

}  // namespace voroudf
