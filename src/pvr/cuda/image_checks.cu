#include "pvr/cuda/image_checks.h"

#include <algorithm>

#include "pvr/cuda/cuda_util.cuh"

namespace pvr::cuda {
namespace {

constexpr unsigned kThreads = 256;

// Grid-stride: each thread counts its pixels, one atomic per block.
__global__ void countNonFiniteKernel(const Vec3* image, size_t pixels, unsigned long long* total) {
  __shared__ unsigned blockCount;
  if (threadIdx.x == 0) blockCount = 0;
  __syncthreads();
  unsigned mine = 0;
  for (size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x; i < pixels; i += size_t(gridDim.x) * blockDim.x) {
    const Vec3 p = image[i];
    mine += !(isfinite(p.x) && isfinite(p.y) && isfinite(p.z));
  }
  if (mine) atomicAdd(&blockCount, mine);
  __syncthreads();
  if (threadIdx.x == 0 && blockCount) atomicAdd(total, (unsigned long long)blockCount);
}

}  // namespace

NonFiniteCounter::~NonFiniteCounter() {
  if (counters_) deviceFree(counters_, 2 * sizeof(unsigned long long));
}

void NonFiniteCounter::count(const Vec3* const images[2], size_t pixels, void* stream, uint64_t counts[2]) {
  counts[0] = counts[1] = 0;
  if (!pixels || (!images[0] && !images[1])) return;
  auto s = static_cast<cudaStream_t>(stream);
  if (!counters_) counters_ = static_cast<unsigned long long*>(deviceAllocate(2 * sizeof(unsigned long long), "non-finite pixel counts"));
  PVR_CUDA_CHECK(cudaMemsetAsync(counters_, 0, 2 * sizeof(unsigned long long), s));
  // A few blocks per SM are enough for a memory-bound scan.
  const unsigned blocks = std::min(blocksFor(pixels, kThreads), 4096u);
  for (int e = 0; e < 2; ++e)
    if (images[e]) launch("non-finite pixel count", countNonFiniteKernel, blocks, kThreads, 0, s, images[e], pixels, counters_ + e);
  unsigned long long host[2] = {0, 0};
  PVR_CUDA_CHECK(cudaMemcpyAsync(host, counters_, sizeof host, cudaMemcpyDeviceToHost, s));
  PVR_CUDA_CHECK(cudaStreamSynchronize(s));
  counts[0] = host[0], counts[1] = host[1];
}

}  // namespace pvr::cuda
