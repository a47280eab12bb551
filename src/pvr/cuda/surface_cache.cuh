#pragma once
// The surface cache on the GPU (photon/surface_cache.h): its table in device memory, sized by the
// host's rule (surfaceCacheCapacity) from the cells of the frame before, so the CPU and the GPU
// make the same cells. Insertion sums a warp's points of one cell before one lane adds them (a
// cell spans many neighbouring pixels); each new cell is estimated by a block (hash grid, radius
// estimate) or a thread (kNN, kd-tree); then every pixel looks its estimate up.
#include "pvr/cuda/eye_pass.cuh"
#include "pvr/photon/surface_cache.h"

namespace pvr::cuda {

class GpuSurfaceCache {
 public:
  void invalidate() { stale_ = true; }  ///< a new photon map: the next prepare() empties the table
  // Before a cached pass: after invalidate(), sizes the table for up to `points` gather points of
  // the frame and empties it.
  void prepare(float cellSize, size_t points, cudaStream_t stream);
  // One pass: the n gather points (pixel i's at i) enter the cache, the new cells are estimated,
  // and each pixel's sample is stored into image (finishGatherCached).
  void estimate(DeviceMap map, const DensityParams& density, GatherPointStore points, uint32_t n, int sample,
                int samples, Vec3* image, cudaStream_t stream);
  // Queues the copy of the counters (cells, points without a slot) for the frame's end.
  void downloadCounters(cudaStream_t stream);
  // After the frame's work: the cells and the points without a slot since the last prepare().
  size_t cells() const { return hostCounters_[1]; }
  size_t unplacedPoints() const { return hostCounters_[2]; }
  size_t memoryBytes() const;

 private:
  SurfaceCacheView view() const;
  DeviceBuffer<unsigned long long> keys_;
  DeviceBuffer<SurfaceCellSums> sums_;
  DeviceBuffer<SurfaceCellEstimate> estimates_;
  DeviceBuffer<uint32_t> created_, counters_;
  uint32_t capacity_ = 0, pass_ = 0;
  float cellSize_ = 1.0f;
  bool stale_ = true;
  uint32_t hostCounters_[3] = {0, 0, 0};
};

}  // namespace pvr::cuda
