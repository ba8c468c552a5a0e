#pragma once
// A counter-based random number generator: every draw is a pure function of (seed, stream
// keys, counter), so the CPU and CUDA backends draw the same numbers in any order, on any
// number of threads, with no state to carry between launches. The mixer is splitmix64's
// finalizer, which passes BigCrush when fed a counter.
#include <cstdint>

#include "core/jet_layout.hpp"  // YH_HD

namespace yarnhom {

YH_HD inline uint64_t rng_mix(uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// A key for one stream of draws, e.g. (seed, network, purpose, epoch, batch).
YH_HD inline uint64_t rng_key(uint64_t seed, uint64_t a, uint64_t b = 0, uint64_t c = 0,
                              uint64_t d = 0) {
  uint64_t k = rng_mix(seed);
  k = rng_mix(k ^ (a + 0x632be59bd9b4e019ull));
  k = rng_mix(k ^ (b + 0x85157af5ull));
  k = rng_mix(k ^ (c + 0x2545f4914f6cdd1dull));
  return rng_mix(k ^ (d + 0x9e3779b97f4a7c15ull));
}

YH_HD inline uint64_t rng_bits(uint64_t key, uint64_t counter) {
  return rng_mix(key ^ rng_mix(counter));
}

// Uniform in [0, 1) with 53 (double) or 24 (float) random bits.
YH_HD inline double rng_uniform(uint64_t key, uint64_t counter) {
  return static_cast<double>(rng_bits(key, counter) >> 11) * 0x1.0p-53;
}
YH_HD inline float rng_uniformf(uint64_t key, uint64_t counter) {
  return static_cast<float>(rng_bits(key, counter) >> 40) * 0x1.0p-24f;
}

// Purposes of the training streams (the `a` argument of rng_key after the network index).
enum RngPurpose : uint64_t {
  kRngInit = 1,      // weight initialization
  kRngSplit = 2,     // train/validation split
  kRngShuffle = 3,   // per-epoch shuffle
  kRngOffDomain = 4, // per-batch off-domain points
  kRngValOffDomain = 5,  // the fixed validation off-domain points
};

}  // namespace yarnhom
