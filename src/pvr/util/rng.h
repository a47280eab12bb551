#pragma once
// Counter-based random numbers: every draw is a pure function of (seed, stream index, bounce,
// dimension), so the CPU and CUDA backends draw identical numbers for the same photon or pixel
// regardless of thread scheduling.
#include "pvr/pvr.h"
#include "pvr/util/blue_noise.h"

namespace pvr {

// A 32-bit integer permutation with full avalanche (PCG's RXS-M-XS output step on an LCG step).
PVR_HOST_DEVICE inline uint32_t hash32(uint32_t v) {
  uint32_t state = v * 747796405u + 2891336453u;
  uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

// Order-dependent: hashCombine(a, b) != hashCombine(b, a), so (seed, index) never aliases (index, seed).
PVR_HOST_DEVICE inline uint32_t hashCombine(uint32_t seed, uint32_t v) { return hash32(seed * 0x9E3779B1u + hash32(v)); }

// Uniform float in [0, 1) from the top 24 bits.
PVR_HOST_DEVICE inline float toUnitFloat(uint32_t bits) { return float(bits >> 8) * (1.0f / 16777216.0f); }

// One random stream: a key fixed by (seed, index, bounce) and a counter for the dimension. A
// pixel's stream may take its first kBlueNoiseDims dimensions from blue-noise dithered sequences
// (useBlueNoise); the later ones stay hashed.
class CounterRng {
 public:
  PVR_HOST_DEVICE CounterRng(uint32_t seed, uint32_t index, uint32_t bounce)
      : key_(hashCombine(hashCombine(hash32(seed), index), bounce)) {}
  // Dimensions 0 .. kBlueNoiseDims-1 from blueNoiseBits of pixel (x, y), sample number `index`.
  PVR_HOST_DEVICE void useBlueNoise(uint32_t x, uint32_t y, uint32_t index, uint32_t scramble) {
    blueDims_ = kBlueNoiseDims;
    pixel_ = (x % kBlueNoiseSize) | (y % kBlueNoiseSize) << 16;
    index_ = index, scramble_ = scramble;
  }
  PVR_HOST_DEVICE float uniform() { return toUnitFloat(nextBits()); }
  PVR_HOST_DEVICE uint32_t nextBits() {
    const uint32_t d = counter_++;
    if (d < blueDims_) return blueNoiseBits(pixel_ & 0xffffu, pixel_ >> 16, d, index_, scramble_);
    return hashCombine(key_, d);
  }

 private:
  uint32_t key_;
  uint32_t counter_ = 0;
  uint32_t blueDims_ = 0, pixel_ = 0, index_ = 0, scramble_ = 0;
};

}  // namespace pvr
