#include "pvr/cuda/denoise.cuh"

#include <algorithm>

#include "pvr/util/error.h"

namespace pvr::cuda {
namespace {

constexpr int kBlock = 16;
constexpr unsigned kListThreads = 256;

__device__ inline bool blockPixel(const EyeCamera& c, int& x, int& y) {
  x = int(blockIdx.x) * kBlock + int(threadIdx.x);
  y = int(blockIdx.y) * kBlock + int(threadIdx.y);
  return x < c.width && y < c.height;
}

// Appends `value` to list[*count] for each thread of the warp whose flag is set, one atomic per
// warp: a warp's pixels (two rows of 16 neighbours) stay together, so the later passes' taps are
// as coherent as over the whole image.
__device__ inline void appendInWarp(uint32_t* list, unsigned* count, bool flag, uint32_t value) {
  const unsigned active = __activemask();
  const unsigned set = __ballot_sync(active, flag);
  if (!set) return;
  const unsigned lane = (threadIdx.y * blockDim.x + threadIdx.x) & 31u;
  const unsigned leader = unsigned(__ffs(int(set)) - 1);
  unsigned base = 0;
  if (lane == leader) base = atomicAdd(count, unsigned(__popc(int(set))));
  base = __shfl_sync(active, base, int(leader));
  if (flag) list[base + unsigned(__popc(int(set & ((1u << lane) - 1u))))] = value;
}

__global__ void accumulateKernel(DenoiseFrameView v, uint32_t* filtered, unsigned* filteredCount) {
  int x, y;
  const bool inside = blockPixel(v.camera, x, y);
  const size_t pixel = inside ? denoisePixel(v.camera, x, y) : 0;
  if (inside) accumulateDenoisePixel(v, x, y);
  appendInWarp(filtered, filteredCount, inside && filtersPixel(v, pixel), uint32_t(pixel));
}

// The later passes: a grid-stride loop over the listed pixels.
template <class Pass>
__device__ inline void forEachListed(const DenoiseFrameView& v, const uint32_t* pixels, const unsigned* count, Pass pass) {
  const unsigned n = *count;
  for (unsigned i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += gridDim.x * blockDim.x) {
    const uint32_t pixel = pixels[i];
    pass(int(pixel % unsigned(v.camera.width)), int(pixel / unsigned(v.camera.width)));
  }
}

__global__ void varianceKernel(DenoiseFrameView v, const uint32_t* pixels, const unsigned* count) {
  forEachListed(v, pixels, count, [&](int x, int y) { estimateDenoiseVariance(v, x, y); });
}

__global__ void atrousKernel(DenoiseFrameView v, int iteration, const uint32_t* pixels, const unsigned* count) {
  forEachListed(v, pixels, count, [&](int x, int y) { atrousDenoisePixel(v, iteration, x, y); });
}

__global__ void remodulateKernel(DenoiseFrameView v, const uint32_t* pixels, const unsigned* count) {
  forEachListed(v, pixels, count, [&](int x, int y) { remodulateAccumulated(v, x, y); });
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
  const int levels = in.keepLevels ? params.iterations + 1 : 2;
  for (int s = 0; s < signals; ++s) {
    next.colour[s].reserve(pixels, "denoiser history");
    for (int k = 0; k < levels; ++k) state.levels[s][k].reserve(pixels, "denoiser filter levels");
  }
  next.moments.reserve(4 * pixels, "denoiser moments");
  next.length.reserve(pixels, "denoiser history length");
  next.guide.reserve(pixels, "denoiser guides");
  state.albedo.reserve(pixels, "denoiser albedo");
  state.depthGradient.reserve(2 * pixels, "denoiser depth gradient");
  state.out.reserve(pixels, "denoised image");
  state.filteredPixels.reserve(pixels, "denoiser pixel list");
  filteredCount_.reserve(2, "denoiser pixel count");

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
    for (int k = 0; k < kDenoiseLevels; ++k)
      v.filtered[s][k] = state.levels[s][in.keepLevels ? std::min(k, levels - 1) : k & 1].data();
    v.historyOut[s] = next.colour[s].data();
  }
  v.out = state.out.data();
  if (in.reusedFrom) {
    const EyeState& left = eyes_[int(Eye::Left)];
    if (eye != Eye::Right || !left.valid || left.keptLevels < params.iterations + 1 || left.signals != signals ||
        !in.sourceDenoised)
      throw Error("the right eye's denoise reuses the left eye's, which did not keep its levels this frame");
    const History& shared = left.history[left.latest];
    for (int s = 0; s < signals; ++s) {
      v.source.history[s] = shared.colour[s].data();
      for (int k = 0; k <= params.iterations; ++k) v.source.levels[s][k] = left.levels[s][k].data();
    }
    v.source.moments = shared.moments.data();
    v.source.length = shared.length.data();
  }

  const dim3 grid(unsigned((camera.width + kBlock - 1) / kBlock), unsigned((camera.height + kBlock - 1) / kBlock));
  const dim3 block(kBlock, kBlock);
  uint32_t* list = state.filteredPixels.data();
  unsigned* count = filteredCount_.data() + e;
  // The list's length stays on the device: its passes loop over whatever it holds.
  const unsigned listBlocks = std::min(blocksFor(pixels, kListThreads), unsigned(8 * multiprocessorCount()));
  PVR_CUDA_CHECK(cudaMemsetAsync(count, 0, sizeof(unsigned), stream));
  launch("denoise accumulate", accumulateKernel, grid, block, 0, stream, v, list, count);
  if (params.iterations == 0) {
    launch("denoise remodulate", remodulateKernel, listBlocks, kListThreads, 0, stream, v, list, count);
  } else {
    launch("denoise variance", varianceKernel, listBlocks, kListThreads, 0, stream, v, list, count);
    for (int i = 0; i < params.iterations; ++i)
      launch("denoise a-trous", atrousKernel, listBlocks, kListThreads, 0, stream, v, i, list, count);
  }
  state.latest ^= 1;
  state.camera = camera;
  state.signals = signals;
  state.keptLevels = in.keepLevels ? levels : 0;
  state.valid = true;
}

size_t GpuDenoiser::memoryBytes() const {
  size_t bytes = filteredCount_.bytes();
  for (const EyeState& s : eyes_) {
    bytes += s.history[0].bytes() + s.history[1].bytes() + s.albedo.bytes() + s.depthGradient.bytes() + s.out.bytes() +
             s.filteredPixels.bytes();
    for (int k = 0; k < 2; ++k)
      for (const auto& level : s.levels[k]) bytes += level.bytes();
  }
  return bytes;
}

}  // namespace pvr::cuda
