#pragma once
// The blue-noise mask behind PixelSampling::BlueNoise (util/blue_noise.h), made by Ulichney's
// void-and-cluster method: every threshold of the ranks gives a binary pattern whose points are
// evenly spread (blue noise), so the mask's values (ranks / size^2) dither a per-pixel rotation of
// the samples. The mask photonvr uses is this function's output, kept in blue_noise_mask.inc (a
// test regenerates it and compares).
#include <cstdint>
#include <vector>

namespace pvr {

// Ranks 0 .. size^2 - 1, row-major, each once: a size x size tile (toroidal) of void-and-cluster
// blue noise with a Gaussian energy filter of standard deviation `sigma` pixels. Deterministic
// (integer energies). size 4..256.
std::vector<uint16_t> voidAndClusterRanks(int size, double sigma = 1.9, uint32_t seed = 1);

}  // namespace pvr
