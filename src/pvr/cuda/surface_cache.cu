#include "pvr/cuda/eye_kernels.cuh"
#include "pvr/cuda/surface_cache.cuh"
#include "pvr/photon/host_surface_cache.h"

namespace pvr::cuda {
namespace {

struct DeviceAtomics {
  __device__ unsigned long long load64(unsigned long long* p) const { return *reinterpret_cast<volatile unsigned long long*>(p); }
  __device__ unsigned long long cas64(unsigned long long* p, unsigned long long expected, unsigned long long desired) const {
    return atomicCAS(p, expected, desired);
  }
  __device__ void add64(unsigned long long* p, unsigned long long v) const { atomicAdd(p, v); }
  __device__ uint32_t add32(uint32_t* p, uint32_t v) const { return atomicAdd(p, v); }
  __device__ uint32_t load32(uint32_t* p) const { return *reinterpret_cast<volatile uint32_t*>(p); }
  __device__ void store32(uint32_t* p, uint32_t v) const { atomicExch(p, v); }
};

// The sum over the lanes of `group` (each lane of it calls with the same group), modulo 2^32.
__device__ inline unsigned groupSum(unsigned group, unsigned value) {
#if __CUDA_ARCH__ >= 800
  return __reduce_add_sync(group, value);
#else
  unsigned sum = 0;
  for (unsigned rest = group; rest; rest &= rest - 1) sum += __shfl_sync(group, value, __ffs(rest) - 1);
  return sum;
#endif
}

__global__ void insertKernel(SurfaceCacheView cache, GatherPointStore points, uint32_t n) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  uint64_t key = kNoSurfaceCell;
  SurfaceCellSums sums{};
  if (i < n) {
    const GatherPointCore c = points.coreAt(i);
    if (cachesEstimate(c.lobes, c.weight)) {
      int cell[3];
      key = surfaceCellKeyOf(cache, c.position, c.normal, cell);
      if (key != kNoSurfaceCell) sums = surfacePointSums(c.position, c.normal, cell, cache.invCellSize);
    }
  }
  const unsigned group = __match_any_sync(0xffffffffu, key);  // every lane takes part
  if (key == kNoSurfaceCell) return;
  // A point's parts are below 2^24 in magnitude, so a warp's sums fit 32 bits.
  SurfaceCellSums total{};
  for (int a = 0; a < 3; ++a) {
    total.position[a] = groupSum(group, unsigned(sums.position[a]));
    total.normal[a] = (unsigned long long)(long long)int(groupSum(group, unsigned(sums.normal[a])));
  }
  total.count = unsigned(__popc(group));
  if ((threadIdx.x & 31u) == unsigned(__ffs(group) - 1)) addToSurfaceCell(cache, key, total, DeviceAtomics());
}

// A block per new cell, its threads splitting each row's photons (the hash grid's radius
// estimate): a cell's candidates are the 27 map cells around it, tens of thousands of photons at
// large radii, and there may be only a few thousand cells to spread over the GPU.
constexpr int kCellBlock = 128;
__global__ void __launch_bounds__(kCellBlock) estimateCellsBlockKernel(SurfaceCacheView cache, HashGridView map, float radius) {
  __shared__ Vec3 warpSums[kCellBlock / 32];
  const unsigned lane = threadIdx.x & 31u, warp = threadIdx.x >> 5;
  const float r2 = radius * radius;
  const uint32_t n = cache.counters[0];
  for (uint32_t i = blockIdx.x; i < n; i += gridDim.x) {  // block-uniform
    const uint32_t slot = cache.created[i];
    SurfaceCellEstimate e;
    Vec3 normal;
    surfaceCellPoint(cache, slot, e.point, normal);
    Vec3 sum{0, 0, 0};
    const int64_t cell = map.photonCount ? map.cellOf(e.point) : -1;
    for (int row = 0; cell >= 0 && row < 9; ++row) {
      const uint32_t first = uint32_t(cell + map.rowOffsets[row]);
      const uint32_t end = map.cellStart[first + 3];
      for (uint32_t j = map.cellStart[first] + threadIdx.x; j < end; j += kCellBlock)
        if (photonDistance2(e.point, map.position(j)) <= r2 && photonFacesSurface(map.photons[j].direction, normal))
          sum += map.photons[j].power;
    }
    for (int offset = 16; offset > 0; offset >>= 1) {
      sum.x += __shfl_xor_sync(0xffffffffu, sum.x, offset);
      sum.y += __shfl_xor_sync(0xffffffffu, sum.y, offset);
      sum.z += __shfl_xor_sync(0xffffffffu, sum.z, offset);
    }
    if (lane == 0) warpSums[warp] = sum;
    __syncthreads();
    if (threadIdx.x == 0) {
      Vec3 total = warpSums[0];
      for (int w = 1; w < kCellBlock / 32; ++w) total += warpSums[w];
      e.flux = total * (1.0f / (kPi * r2));
      cache.estimates[slot] = e;
    }
    __syncthreads();  // warpSums is reused by the next cell
  }
}

// A thread per new cell (kNN, or the kd-tree).
template <class Map, Estimator E>
__global__ void estimateCellsKernel(SurfaceCacheView cache, Map map, DensityParams density) {
  density.estimator = E;
  const uint32_t n = cache.counters[0];
  for (uint32_t i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += gridDim.x * blockDim.x)
    estimateSurfaceCell(cache, map, cache.created[i], density);
}

template <class Map, Estimator E>
__global__ void lookupKernel(SurfaceCacheView cache, Map map, DensityParams density, GatherPointStore points, uint32_t n,
                             int sample, int samples, Vec3* image) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  density.estimator = E;
  storeSample(image, i, finishGatherCached(cache, map, points.load(i), density), sample, samples);
}

template <class Map>
void estimateWith(const SurfaceCacheView& cache, const Map& map, const DensityParams& density, GatherPointStore points,
                  uint32_t n, int sample, int samples, Vec3* image, cudaStream_t stream) {
  const bool knn = density.estimator == Estimator::Knn;
  const unsigned blocks = unsigned(multiprocessorCount()) * 8u;  // grid-stride over the new cells
  if constexpr (std::is_same_v<Map, HashGridView>) {
    if (!knn)
      launch("surface cache estimates (block per cell)", estimateCellsBlockKernel, unsigned(multiprocessorCount()) * 16u,
             unsigned(kCellBlock), 0, stream, cache, map, density.radius);
    else launch("surface cache estimates", estimateCellsKernel<Map, Estimator::Knn>, blocks, 128, 0, stream, cache, map, density);
  } else {
    if (knn) launch("surface cache estimates", estimateCellsKernel<Map, Estimator::Knn>, blocks, 128, 0, stream, cache, map, density);
    else launch("surface cache estimates", estimateCellsKernel<Map, Estimator::Radius>, blocks, 128, 0, stream, cache, map, density);
  }
  auto* lookup = knn ? lookupKernel<Map, Estimator::Knn> : lookupKernel<Map, Estimator::Radius>;
  launch("surface cache look-ups", lookup, blocksFor(n, 256), 256, 0, stream, cache, map, density, points, n, sample,
         samples, image);
}

}  // namespace

SurfaceCacheView GpuSurfaceCache::view() const {
  SurfaceCacheView v;
  v.keys = keys_.data();
  v.sums = sums_.data();
  v.estimates = estimates_.data();
  v.created = created_.data();
  v.counters = counters_.data();
  v.capacity = capacity_;
  v.pass = pass_;
  v.cellSize = cellSize_;
  v.invCellSize = 1.0f / cellSize_;
  return v;
}

void GpuSurfaceCache::prepare(float cellSize, size_t points, cudaStream_t stream) {
  if (!stale_) return;
  capacity_ = surfaceCacheCapacity(points, hostCounters_[1]);
  keys_.reserve(capacity_, "surface cache keys");
  sums_.reserve(capacity_, "surface cache sums");
  estimates_.reserve(capacity_, "surface cache estimates");
  created_.reserve(capacity_, "surface cache new cells");
  counters_.reserve(3, "surface cache counters");
  PVR_CUDA_CHECK(cudaMemsetAsync(keys_.data(), 0xff, capacity_ * sizeof(unsigned long long), stream));
  PVR_CUDA_CHECK(cudaMemsetAsync(sums_.data(), 0, capacity_ * sizeof(SurfaceCellSums), stream));
  PVR_CUDA_CHECK(cudaMemsetAsync(counters_.data(), 0, 3 * sizeof(uint32_t), stream));
  cellSize_ = cellSize;
  pass_ = 0;
  stale_ = false;
}

void GpuSurfaceCache::estimate(DeviceMap map, const DensityParams& density, GatherPointStore points, uint32_t n,
                               int sample, int samples, Vec3* image, cudaStream_t stream) {
  ++pass_;
  PVR_CUDA_CHECK(cudaMemsetAsync(counters_.data(), 0, sizeof(uint32_t), stream));  // this pass's new cells
  const SurfaceCacheView cache = view();
  launch("surface cache insertion", insertKernel, blocksFor(n, 256), 256, 0, stream, cache, points, n);
  if (map.grid) estimateWith(cache, *map.grid, density, points, n, sample, samples, image, stream);
  else estimateWith(cache, *map.tree, density, points, n, sample, samples, image, stream);
}

void GpuSurfaceCache::downloadCounters(cudaStream_t stream) {
  if (capacity_ == 0) return;
  PVR_CUDA_CHECK(cudaMemcpyAsync(hostCounters_, counters_.data(), sizeof hostCounters_, cudaMemcpyDeviceToHost, stream));
}

size_t GpuSurfaceCache::memoryBytes() const {
  return keys_.bytes() + sums_.bytes() + estimates_.bytes() + created_.bytes() + counters_.bytes();
}

}  // namespace pvr::cuda
