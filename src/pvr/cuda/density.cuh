#pragma once
// Density estimation on the GPU at gather points the eye pass wrote: the hybrid scheme's tiled
// kernel, the paper's Algorithm 1 (shared memory), estimates in cell order, a warp per listed
// point (sparse points), and a thread per listed point (kNN, the kd-tree).
#include "pvr/cuda/eye_pass.cuh"

namespace pvr::cuda {

#ifdef __CUDACC__
// CUB select predicate: the gather points that still need an estimate.
struct NeedsEstimate {
  GatherPointStore points;
  __device__ bool operator()(uint32_t pixel) const { return points.needsEstimate(pixel); }
};
#endif

// One estimate per gather point of a width x height image, a thread each in 8x8 tiles (hybrid).
void estimateTiled(DeviceMap map, const DensityParams& density, GatherPointStore points, int width, int height,
                   int sample, int samples, Vec3* image, cudaStream_t stream);
// The paper's Algorithm 1 (hash grid).
void estimateSharedMemory(const HashGridView& map, const DensityParams& density, GatherPointStore points, int width,
                          int height, int sample, int samples, Vec3* image, cudaStream_t stream);
// Cell keys of n gather points (noCell: none needed) with their indices, for sorting by cell.
void writeCellKeysOfPoints(const HashGridView& map, GatherPointStore points, uint32_t n, uint32_t noCell,
                           uint32_t* keys, uint32_t* values, cudaStream_t stream);
// Estimates the points in `order` (consecutive threads, consecutive cells).
void estimateInOrder(const HashGridView& map, const DensityParams& density, GatherPointStore points,
                     const uint32_t* order, uint32_t n, int sample, int samples, Vec3* image, cudaStream_t stream);
// Stores the points that need no estimate (reused, or no diffuse surface) as they are.
void storeWithoutEstimate(GatherPointStore points, uint32_t n, int sample, int samples, Vec3* image,
                          cudaStream_t stream);
// Radius estimates of the listed points (*listed of them, indices into points/image), a warp each.
void estimateWarpPerPoint(const HashGridView& map, float radius, GatherPointStore points, const uint32_t* list,
                          const uint32_t* listed, int sample, int samples, Vec3* image, cudaStream_t stream);
// Estimates of the listed points, a thread each, into colours[point]; maxListed bounds *listed.
void estimateListed(DeviceMap map, const DensityParams& density, GatherPointStore points, const uint32_t* list,
                    const uint32_t* listed, uint32_t maxListed, Vec3* colours, cudaStream_t stream);

}  // namespace pvr::cuda
