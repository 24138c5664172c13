// Counter-based random numbers: every stream is keyed by (seed, pass, item, purpose), so the
// numbers a photon or a pixel sees do not depend on which thread runs it or in what order.
#pragma once

#include <cstdint>

namespace pb {

// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mixer.
inline uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Purposes separate the streams that share a (pass, item) key.
enum class Stream : uint64_t { Photon = 1, DirectLight = 2, Test = 3, Camera = 4 };

// PCG32 (O'Neill 2014, XSH-RR output) seeded from a hashed key.
class Rng {
 public:
  Rng(uint64_t seed, uint64_t pass, uint64_t item, Stream stream) {
    const uint64_t k = mix64(seed ^ mix64(pass + 0x9e3779b97f4a7c15ULL * (1 + uint64_t(stream))));
    state_ = mix64(k ^ mix64(item));
    inc_ = (mix64(k + item * 0xd1b54a32d192ed03ULL) << 1) | 1u;
    next_u32();
  }

  uint32_t next_u32() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    const uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    const uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((-rot) & 31));
  }

  // Uniform in [0, 1): 24 random bits, so the result is exactly representable and never 1.
  float next_float() { return float(next_u32() >> 8) * 0x1p-24f; }
  double next_double() {
    const uint64_t hi = next_u32(), lo = next_u32();
    return double(((hi << 32) | lo) >> 11) * 0x1p-53;
  }

 private:
  uint64_t state_;
  uint64_t inc_;
};

}  // namespace pb
