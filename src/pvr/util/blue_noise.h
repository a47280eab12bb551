#pragma once
// Blue-noise dithered low-discrepancy samples for the first dimensions of a pixel's random stream
// (PixelSampling::BlueNoise): the sub-pixel position and the light sample that a pixel draws first.
// Dimension d of sample number `index` of a pixel is point `index` of Halton's sequence (bases 2,
// 3, 5, 7, 11: successive frames of one pixel stratify, jointly over the dimensions, which TAA,
// the denoiser and a still head's refinement accumulate) rotated by the pixel's rank in a 64x64
// void-and-cluster mask (neighbouring pixels get far-apart values, so one frame's error is
// high-frequency noise that any spatial filter, the eye included, removes more of). Each dimension
// reads the mask at its own toroidal shift and adds its own random rotation, both from
// `scramble`, so over scrambles a value is uniform (as uniform as the hash): unbiased, like the
// white stream it replaces.
#include "pvr/pvr.h"

namespace pvr {

constexpr int kBlueNoiseSize = 64;         ///< the mask's side (it tiles the image)
// Leading dimensions of a pixel's stream drawn this way: a jittered sub-pixel position and a light
// sample of three numbers. (Halton's bases past 11 correlate over the first tens of frames.)
constexpr uint32_t kBlueNoiseDims = 5;

// The mask: void-and-cluster ranks 0..4095 (util/blue_noise_generator.h made them; a test checks).
#include "pvr/util/blue_noise_mask.inc"

inline constexpr uint16_t kBlueNoiseRanks[kBlueNoiseSize * kBlueNoiseSize] = {PVR_BLUE_NOISE_MASK};
#ifdef __CUDACC__
// Device code cannot read a host constexpr array: the same values in device memory (each
// translation unit has its own 8 KB copy, read through the read-only cache).
static __device__ const uint16_t kBlueNoiseRanksDevice[kBlueNoiseSize * kBlueNoiseSize] = {PVR_BLUE_NOISE_MASK};
#endif

PVR_HOST_DEVICE inline uint32_t blueNoiseRank(uint32_t x, uint32_t y) {
  const uint32_t i = (y % kBlueNoiseSize) * kBlueNoiseSize + x % kBlueNoiseSize;
#ifdef __CUDA_ARCH__
  return __ldg(&kBlueNoiseRanksDevice[i]);
#else
  return kBlueNoiseRanks[i];
#endif
}

// The radical inverse of `index` in base b (Halton's sequence: dimension d uses the d-th prime) as
// a 32-bit fraction, in integers so that the CPU and the GPU agree to the bit. Digits past 2^-32
// are dropped.
PVR_HOST_DEVICE inline uint32_t radicalInverseBits(uint32_t index, uint32_t base) {
  if (base == 2) {
#ifdef __CUDA_ARCH__
    return __brev(index);
#else
    uint32_t v = index;
    v = (v >> 16) | (v << 16);
    v = ((v & 0xff00ff00u) >> 8) | ((v & 0x00ff00ffu) << 8);
    v = ((v & 0xf0f0f0f0u) >> 4) | ((v & 0x0f0f0f0fu) << 4);
    v = ((v & 0xccccccccu) >> 2) | ((v & 0x33333333u) << 2);
    return ((v & 0xaaaaaaaau) >> 1) | ((v & 0x55555555u) << 1);
#endif
  }
  uint64_t value = 0, denominator = 1;
  while (index && denominator * base <= (uint64_t(1) << 32)) {
    value = value * base + index % base;
    denominator *= base;
    index /= base;
  }
  return uint32_t((value << 32) / denominator);
}

PVR_HOST_DEVICE inline uint32_t haltonBase(uint32_t d) { return d == 0 ? 2u : d == 1 ? 3u : d == 2 ? 5u : d == 3 ? 7u : 11u; }

// The 32 random bits of dimension d (< kBlueNoiseDims) of pixel (x, y)'s sample number `index`.
PVR_HOST_DEVICE inline uint32_t blueNoiseBits(uint32_t x, uint32_t y, uint32_t d, uint32_t index, uint32_t scramble) {
  uint32_t h = scramble * 0x9E3779B1u + d * 0x85EBCA77u;  // per-dimension shift and rotation
  h ^= h >> 15, h *= 0x2C1B3C6Du, h ^= h >> 12, h *= 0x297A2D39u, h ^= h >> 15;
  const uint32_t rank = blueNoiseRank(x + (h & 63u), y + ((h >> 6) & 63u));
  uint32_t rotation = h * 0x9E3779B1u;
  rotation ^= rotation >> 16, rotation *= 0x85EBCA6Bu, rotation ^= rotation >> 13;
  return (rank << 20) + radicalInverseBits(index, haltonBase(d)) + rotation;
}

}  // namespace pvr
