#include "pvr/cuda/denoise.cuh"

namespace pvr::cuda {
namespace {

constexpr int kBlock = 16;

__device__ inline bool blockPixel(const EyeCamera& c, int& x, int& y) {
  x = int(blockIdx.x) * kBlock + int(threadIdx.x);
  y = int(blockIdx.y) * kBlock + int(threadIdx.y);
  return x < c.width && y < c.height;
}

__global__ void accumulateKernel(DenoiseFrameView v, unsigned* historyPixels) {
  int x, y;
  const bool inside = blockPixel(v.camera, x, y);
  countInWarp(historyPixels, inside && accumulateDenoisePixel(v, x, y));
}

__global__ void varianceKernel(DenoiseFrameView v) {
  int x, y;
  if (blockPixel(v.camera, x, y)) estimateDenoiseVariance(v, x, y);
}

__global__ void atrousKernel(DenoiseFrameView v, int iteration) {
  int x, y;
  if (blockPixel(v.camera, x, y)) atrousDenoisePixel(v, iteration, x, y);
}

__global__ void remodulateKernel(DenoiseFrameView v) {
  int x, y;
  if (blockPixel(v.camera, x, y)) remodulateAccumulated(v, x, y);
}

}  // namespace

void GpuDenoiser::denoise(Eye eye, const EyeCamera& camera, const DenoiseParams& params, const DenoiseInputs& in,
                          int stillFrames, cudaStream_t stream) {
  const int e = int(eye);
  EyeState& state = eyes_[e];
  const size_t pixels = size_t(camera.width) * camera.height;
  const int signals = in.direct ? 2 : 1;
  if (state.valid && (state.camera.width != camera.width || state.camera.height != camera.height || state.signals != signals))
    state.valid = false;
  History& previous = state.history[state.latest];
  History& next = state.history[state.latest ^ 1];
  for (int s = 0; s < signals; ++s) {
    next.colour[s].reserve(pixels, "denoiser history");
    state.accumulated[s].reserve(pixels, "denoiser accumulation");
    state.filtered[s][0].reserve(pixels, "denoiser filter");
    state.filtered[s][1].reserve(pixels, "denoiser filter");
  }
  next.moments.reserve(4 * pixels, "denoiser moments");
  next.length.reserve(pixels, "denoiser history length");
  next.guide.reserve(pixels, "denoiser guides");
  state.albedo.reserve(pixels, "denoiser albedo");
  state.depthGradient.reserve(2 * pixels, "denoiser depth gradient");
  state.out.reserve(pixels, "denoised image");
  historyPixels_.reserve(2, "denoiser history count");

  DenoiseFrameView v;
  v.camera = camera;
  v.in = in;
  v.params = params;
  v.stillFrames = stillFrames;
  if (state.valid) {
    v.history.camera = state.camera;
    for (int s = 0; s < signals; ++s) v.history.colour[s] = previous.colour[s].data();
    v.history.moments = previous.moments.data();
    v.history.length = previous.length.data();
    v.history.guide = previous.guide.data();
  }
  v.albedo = state.albedo.data();
  v.depthGradient = state.depthGradient.data();
  v.guide = next.guide.data();
  v.moments = next.moments.data();
  v.length = next.length.data();
  for (int s = 0; s < signals; ++s) {
    v.accumulated[s] = state.accumulated[s].data();
    v.filtered[s][0] = state.filtered[s][0].data();
    v.filtered[s][1] = state.filtered[s][1].data();
    v.historyOut[s] = next.colour[s].data();
  }
  v.out = state.out.data();

  const dim3 grid(unsigned((camera.width + kBlock - 1) / kBlock), unsigned((camera.height + kBlock - 1) / kBlock));
  const dim3 block(kBlock, kBlock);
  PVR_CUDA_CHECK(cudaMemsetAsync(historyPixels_.data() + e, 0, sizeof(unsigned), stream));
  launch("denoise accumulate", accumulateKernel, grid, block, 0, stream, v, historyPixels_.data() + e);
  if (params.iterations == 0) {
    launch("denoise remodulate", remodulateKernel, grid, block, 0, stream, v);
  } else {
    launch("denoise variance", varianceKernel, grid, block, 0, stream, v);
    for (int i = 0; i < params.iterations; ++i) launch("denoise a-trous", atrousKernel, grid, block, 0, stream, v, i);
  }
  state.latest ^= 1;
  state.camera = camera;
  state.signals = signals;
  state.valid = true;
}

void GpuDenoiser::downloadHistoryPixels(unsigned host[2], cudaStream_t stream) const {
  host[0] = host[1] = 0;
  if (historyPixels_.data())
    PVR_CUDA_CHECK(cudaMemcpyAsync(host, historyPixels_.data(), 2 * sizeof(unsigned), cudaMemcpyDeviceToHost, stream));
}

size_t GpuDenoiser::memoryBytes() const {
  size_t bytes = historyPixels_.bytes();
  for (const EyeState& s : eyes_) {
    bytes += s.history[0].bytes() + s.history[1].bytes() + s.albedo.bytes() + s.depthGradient.bytes() + s.out.bytes();
    for (int k = 0; k < 2; ++k) bytes += s.accumulated[k].bytes() + s.filtered[k][0].bytes() + s.filtered[k][1].bytes();
  }
  return bytes;
}

}  // namespace pvr::cuda
