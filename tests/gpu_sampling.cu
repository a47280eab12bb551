#include "gpu_sampling.h"

#include "pvr/cuda/cuda_util.cuh"
#include "pvr/util/rng.h"

namespace pvr {
namespace {

constexpr int kWords = 13;

PVR_HOST_DEVICE void drawSamples(const SamplerInput& in, uint32_t* out) {
  CounterRng rng(7, in.index ^ in.x, in.y);
  rng.useBlueNoise(in.x, in.y, in.index, in.scramble);
  for (int d = 0; d < 8; ++d) out[d] = rng.nextBits();
  const uint32_t bases[5] = {2, 3, 5, 7, 11};
  for (int b = 0; b < 5; ++b) out[8 + b] = radicalInverseBits(in.index, bases[b]);
}

__global__ void drawSamplesKernel(const SamplerInput* inputs, size_t n, uint32_t* out) {
  const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n) drawSamples(inputs[i], out + i * kWords);
}

}  // namespace

std::vector<uint32_t> drawSamplesOnGpu(const std::vector<SamplerInput>& inputs) {
  cuda::DeviceBuffer<SamplerInput> in;
  cuda::DeviceBuffer<uint32_t> out;
  in.upload(inputs.data(), inputs.size(), "sampler inputs");
  out.reserve(inputs.size() * kWords, "sampler outputs");
  cuda::launch("sampler test", drawSamplesKernel, cuda::blocksFor(inputs.size(), 256), 256, 0, nullptr, in.data(),
               inputs.size(), out.data());
  std::vector<uint32_t> result(inputs.size() * kWords);
  out.download(result.data(), result.size());
  return result;
}

std::vector<uint32_t> drawSamplesOnHost(const std::vector<SamplerInput>& inputs) {
  std::vector<uint32_t> result(inputs.size() * kWords);
  for (size_t i = 0; i < inputs.size(); ++i) drawSamples(inputs[i], result.data() + i * kWords);
  return result;
}

}  // namespace pvr
