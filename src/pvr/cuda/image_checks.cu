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

uint64_t countNonFinitePixels(const Vec3* image, size_t pixels, void* stream) {
  if (!pixels) return 0;
  auto s = static_cast<cudaStream_t>(stream);
  DeviceBuffer<unsigned long long> total;
  total.reserve(1, "non-finite pixel count");
  PVR_CUDA_CHECK(cudaMemsetAsync(total.data(), 0, sizeof(unsigned long long), s));
  // A few blocks per SM are enough for a memory-bound scan.
  const unsigned blocks = std::min(blocksFor(pixels, kThreads), 4096u);
  launch("non-finite pixel count", countNonFiniteKernel, blocks, kThreads, 0, s, image, pixels, total.data());
  unsigned long long count = 0;
  total.download(&count, 1, s);
  return count;
}

}  // namespace pvr::cuda
