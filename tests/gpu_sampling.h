#pragma once
// The blue-noise sampler's numbers, and half-precision conversions, done by the GPU
// (tests/gpu_sampling.cu), for an exact comparison with the host's: both backends must draw the
// same numbers and store the same bits.
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

// util/half_float.h's halfBits of the floats whose bits are k * stride + offset, on the GPU and the host.
std::vector<uint16_t> halfBitsOnGpu(uint32_t stride, uint32_t offset);
std::vector<uint16_t> halfBitsOnHost(uint32_t stride, uint32_t offset);

}  // namespace pvr
