#pragma once
// The random numbers of every stage (docs/design.md "Conventions"), seeded, so that results
// never depend on thread count or evaluation order. Two generators, each kept for the sequences
// it gives: RandomStream (splitmix64), a counter keyed by plain integers, for the draws of one
// item (a module in a derivation step, a leaf's colour, a tree of a forest, a scatter); and
// RandomSequence (the 64-bit Mersenne Twister), one long stream, for the wind's turbulence modes.
// Both turn bits into numbers here, never through std::uniform_real_distribution, which is
// implementation-defined and would make bakes differ between standard libraries.
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

namespace treeanim {

// 64 random bits => a double uniform in [0, 1) (the top 53 bits).
inline double uniform_from_bits(uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }

// splitmix64's output function: a bijective mix of 64 bits.
inline uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Counter-based random numbers (splitmix64): a stream is its 64-bit state, so the draws of an
// item depend only on the integers that key it, never on the items drawn before it.
struct RandomStream {
  uint64_t state = 0;
  // (seed, purpose, step, position) => that item's stream.
  static RandomStream keyed(uint64_t seed, uint64_t purpose, uint64_t step, uint64_t position) {
    return {mix64(mix64(mix64(mix64(seed) ^ purpose) ^ step) ^ position)};
  }
  uint64_t next_u64() {
    state += 0x9e3779b97f4a7c15ULL;
    return mix64(state);
  }
  double uniform() { return uniform_from_bits(next_u64()); }  // [0, 1)
  // Mean 0, standard deviation 1 (Box-Muller).
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]: log is finite
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }
};

// One long stream from a seed (std::mt19937_64, whose sequence the standard fixes).
class RandomSequence {
 public:
  explicit RandomSequence(uint64_t seed) : engine_(seed) {}
  double uniform() { return uniform_from_bits(engine_()); }  // [0, 1)

 private:
  std::mt19937_64 engine_;
};

}  // namespace treeanim
