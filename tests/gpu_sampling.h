#pragma once
// The blue-noise sampler's numbers drawn by the GPU (tests/gpu_sampling.cu), for an exact
// comparison with the host's: both backends must draw the same numbers to the bit.
#include <cstdint>
#include <vector>

namespace pvr {

struct SamplerInput {
  uint32_t x, y, index, scramble;
};

// For each input: a CounterRng's first 8 draws after useBlueNoise(x, y, index, scramble) (5 blue,
// 3 hashed), then radicalInverseBits(index, b) for b = 2, 3, 5, 7, 11: 13 words per input.
std::vector<uint32_t> drawSamplesOnGpu(const std::vector<SamplerInput>& inputs);
std::vector<uint32_t> drawSamplesOnHost(const std::vector<SamplerInput>& inputs);

}  // namespace pvr
