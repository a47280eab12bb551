#include "pvr/cuda/density.cuh"
#include "pvr/cuda/eye_kernels.cuh"

namespace pvr::cuda {
namespace {

// Hybrid, second kernel: one estimate per gather point, in the same 8x8 tiles.
template <class Map, Estimator E>
__global__ void densityKernel(Map map, DensityParams density, GatherPointStore points, int width, int height,
                              int sample, int samples, Vec3* image) {
  int x, y;
  if (!tilePixel(width, height, x, y)) return;
  density.estimator = E;
  size_t pixel = size_t(y) * width + x;
  storeSample(image, pixel, finishGather(map, points.load(pixel), density), sample, samples);
}

// The paper's Algorithm 1. The threads of an 8x8 block find their gather points' cells; if all
// that need an estimate agree on one cell, the block walks that cell's 9 neighbouring rows
// together, each thread staging one photon of every 64 into shared memory, and each thread
// tests all staged photons against its own point. Otherwise each thread estimates alone.
template <Estimator E>
__global__ void __launch_bounds__(kTile* kTile) sharedDensityKernel(HashGridView map, DensityParams density,
                                                                    GatherPointStore points, int width, int height,
                                                                    int sample, int samples, Vec3* image) {
  constexpr int kThreads = kTile * kTile;
  __shared__ Photon staged[kThreads];
  __shared__ int cellMin, cellMax;
  int tid = int(threadIdx.y) * kTile + int(threadIdx.x);
  int x, y;
  bool inside = tilePixel(width, height, x, y);
  size_t pixel = size_t(y) * width + x;
  GatherPoint gp;
  if (inside) gp = points.load(pixel);
  int64_t cell = inside && gp.needsEstimate() ? map.cellOf(gp.position) : -1;
  bool estimating = cell >= 0;  // a point outside the grid has no photons in reach
  if (tid == 0) cellMin = INT_MAX, cellMax = -1;
  __syncthreads();
  if (estimating) {
    atomicMin(&cellMin, int(cell));
    atomicMax(&cellMax, int(cell));
  }
  __syncthreads();
  density.estimator = E;
  Vec3 result = gp.radiance;
  if (cellMin != cellMax) {  // the block disagrees (block-uniform branch)
    if (estimating) result = finishGather(map, gp, density);
  } else if (cellMax >= 0) {
    float r2 = density.radius * density.radius;
    Vec3 sum{0, 0, 0};
    KnnHeap heap(E == Estimator::Knn ? density.k : 1);
    float searchR2 = r2;
    for (int row = 0; row < 9; ++row) {
      uint32_t first = uint32_t(cellMax + map.rowOffsets[row]);
      uint32_t begin = map.cellStart[first], end = map.cellStart[first + 3];
      for (uint32_t base = begin; base < end; base += kThreads) {
        if (base + tid < end) staged[tid] = map.photons[base + tid];
        __syncthreads();
        uint32_t n = end - base < uint32_t(kThreads) ? end - base : uint32_t(kThreads);
        if (estimating) {
          for (uint32_t k = 0; k < n; ++k) {
            float d2 = photonDistance2(gp.position, staged[k].position);
            if (d2 <= searchR2 && photonCounts(staged[k].position - gp.position, staged[k].direction, gp.normal, gp.wall)) {
              if (E == Estimator::Radius) sum += gp.photonContribution(staged[k]);
              else heap.offer(d2, base + k, searchR2);
            }
          }
        }
        __syncthreads();
      }
    }
    if (estimating) {
      Vec3 flux = E == Estimator::Radius
                      ? sum * (1.0f / (kPi * r2))
                      : knnFluxDensity(map, heap, r2, [&](const Photon& p) { return gp.photonContribution(p); });
      result = gp.radiance + gp.weight * flux;
    }
  }
  if (inside) storeSample(image, pixel, result, sample, samples);
}

// Our improvement: gather points sorted by cell, so consecutive threads share their cell.
__global__ void cellKeysOfPointsKernel(HashGridView map, GatherPointStore points, uint32_t n, uint32_t noCell,
                                       uint32_t* keys, uint32_t* values) {
  uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  GatherPoint gp = points.load(i);
  int64_t cell = gp.needsEstimate() ? map.cellOf(gp.position) : -1;
  keys[i] = cell < 0 ? noCell : uint32_t(cell);
  values[i] = i;
}

template <Estimator E>
__global__ void sortedDensityKernel(HashGridView map, DensityParams density, GatherPointStore points,
                                    const uint32_t* order, uint32_t n, int sample, int samples, Vec3* image) {
  uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  density.estimator = E;
  uint32_t pixel = order[i];
  storeSample(image, pixel, finishGather(map, points.load(pixel), density), sample, samples);
}

// Under stereo reuse the right eye is left with a sparse set of gather points (disocclusions,
// edges, whatever is seen through mirrors and glass). One thread per point would leave the GPU
// waiting on a few long chains of dependent loads; instead the points are listed (CUB select) and
// each warp estimates one point, its lanes splitting every cell row's photons (radius estimate).

__global__ void storeWithoutEstimateKernel(GatherPointStore points, uint32_t n, int sample, int samples, Vec3* image) {
  uint32_t pixel = blockIdx.x * blockDim.x + threadIdx.x;
  if (pixel >= n) return;
  GatherPoint gp = points.load(pixel);
  if (!gp.needsEstimate()) storeSample(image, pixel, gp.radiance, sample, samples);
}

__global__ void warpPerPointDensityKernel(HashGridView map, float radius, GatherPointStore points,
                                          const uint32_t* list, const uint32_t* listed, int sample, int samples,
                                          Vec3* image) {
  const unsigned lane = threadIdx.x & 31u;
  const uint32_t warps = (gridDim.x * blockDim.x) >> 5;
  const float r2 = radius * radius;
  const uint32_t n = *listed;
  for (uint32_t i = (blockIdx.x * blockDim.x + threadIdx.x) >> 5; i < n; i += warps) {  // warp-uniform
    uint32_t pixel = list[i];
    GatherPoint gp = points.load(pixel);
    Vec3 sum{0, 0, 0};
    // No estimate for a point without a diffuse surface, or one reused from the other eye.
    int64_t cell = map.photonCount && gp.needsEstimate() ? map.cellOf(gp.position) : -1;
    for (int row = 0; cell >= 0 && row < 9; ++row) {
      uint32_t first = uint32_t(cell + map.rowOffsets[row]);
      uint32_t end = map.cellStart[first + 3];
      for (uint32_t j = map.cellStart[first] + lane; j < end; j += 32) {
        const Vec3 at = map.position(j);
        if (photonDistance2(gp.position, at) <= r2 && photonCounts(at - gp.position, map.photons[j].direction, gp.normal, gp.wall))
          sum += gp.photonContribution(map.photons[j]);
      }
    }
    for (int offset = 16; offset > 0; offset >>= 1) {
      sum.x += __shfl_xor_sync(0xffffffffu, sum.x, offset);
      sum.y += __shfl_xor_sync(0xffffffffu, sum.y, offset);
      sum.z += __shfl_xor_sync(0xffffffffu, sum.z, offset);
    }
    if (lane == 0) storeSample(image, pixel, gp.radiance + gp.weight * (sum * (1.0f / (kPi * r2))), sample, samples);
  }
}

// One thread per listed gather point (kNN, or the kd-tree).
template <class Map, Estimator E>
__global__ void listedDensityKernel(Map map, DensityParams density, GatherPointStore points, const uint32_t* list,
                                    const uint32_t* listed, Vec3* colours) {
  uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= *listed) return;
  density.estimator = E;
  uint32_t vertex = list[i];
  colours[vertex] = finishGather(map, points.load(vertex), density);
}

template <class Map>
void estimateTiledWith(const Map& map, const DensityParams& density, GatherPointStore points, int width, int height,
                       int sample, int samples, Vec3* image, cudaStream_t stream) {
  auto* kernel = density.estimator == Estimator::Knn ? densityKernel<Map, Estimator::Knn> : densityKernel<Map, Estimator::Radius>;
  launch("density estimation", kernel, tileGrid(width, height), dim3(kTile, kTile), 0, stream, map, density, points,
         width, height, sample, samples, image);
}

template <class Map>
void estimateListedWith(const Map& map, const DensityParams& density, GatherPointStore points, const uint32_t* list,
                        const uint32_t* listed, uint32_t maxListed, Vec3* colours, cudaStream_t stream) {
  auto* kernel = density.estimator == Estimator::Knn ? listedDensityKernel<Map, Estimator::Knn>
                                                     : listedDensityKernel<Map, Estimator::Radius>;
  launch("density estimation (listed points)", kernel, blocksFor(maxListed, 128), 128, 0, stream, map, density, points,
         list, listed, colours);
}

}  // namespace

void estimateTiled(DeviceMap map, const DensityParams& density, GatherPointStore points, int width, int height,
                   int sample, int samples, Vec3* image, cudaStream_t stream) {
  if (map.grid) estimateTiledWith(*map.grid, density, points, width, height, sample, samples, image, stream);
  else estimateTiledWith(*map.tree, density, points, width, height, sample, samples, image, stream);
}

void estimateSharedMemory(const HashGridView& map, const DensityParams& density, GatherPointStore points, int width,
                          int height, int sample, int samples, Vec3* image, cudaStream_t stream) {
  auto* kernel = density.estimator == Estimator::Knn ? sharedDensityKernel<Estimator::Knn> : sharedDensityKernel<Estimator::Radius>;
  launch("density estimation (shared memory)", kernel, tileGrid(width, height), dim3(kTile, kTile), 0, stream, map,
         density, points, width, height, sample, samples, image);
}

void writeCellKeysOfPoints(const HashGridView& map, GatherPointStore points, uint32_t n, uint32_t noCell,
                           uint32_t* keys, uint32_t* values, cudaStream_t stream) {
  launch("gather-point cell keys", cellKeysOfPointsKernel, blocksFor(n, 256), 256, 0, stream, map, points, n, noCell,
         keys, values);
}

void estimateInOrder(const HashGridView& map, const DensityParams& density, GatherPointStore points,
                     const uint32_t* order, uint32_t n, int sample, int samples, Vec3* image, cudaStream_t stream) {
  auto* kernel = density.estimator == Estimator::Knn ? sortedDensityKernel<Estimator::Knn> : sortedDensityKernel<Estimator::Radius>;
  launch("density estimation (cell order)", kernel, blocksFor(n, 128), 128, 0, stream, map, density, points, order, n,
         sample, samples, image);
}

void storeWithoutEstimate(GatherPointStore points, uint32_t n, int sample, int samples, Vec3* image,
                          cudaStream_t stream) {
  launch("store without estimate", storeWithoutEstimateKernel, blocksFor(n, 256), 256, 0, stream, points, n, sample,
         samples, image);
}

void estimateWarpPerPoint(const HashGridView& map, float radius, GatherPointStore points, const uint32_t* list,
                          const uint32_t* listed, int sample, int samples, Vec3* image, cudaStream_t stream) {
  launch("density estimation (warp per point)", warpPerPointDensityKernel, unsigned(multiprocessorCount()) * 8u, 256, 0,
         stream, map, radius, points, list, listed, sample, samples, image);
}

void estimateListed(DeviceMap map, const DensityParams& density, GatherPointStore points, const uint32_t* list,
                    const uint32_t* listed, uint32_t maxListed, Vec3* colours, cudaStream_t stream) {
  if (map.grid) estimateListedWith(*map.grid, density, points, list, listed, maxListed, colours, stream);
  else estimateListedWith(*map.tree, density, points, list, listed, maxListed, colours, stream);
}

}  // namespace pvr::cuda
