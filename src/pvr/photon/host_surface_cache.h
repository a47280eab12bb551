#pragma once
// The surface cache's table on the host (surface_cache.h), for the CPU backend: insertion in
// parallel over std::atomic_ref, then one estimate per new cell. The GPU's is
// cuda/surface_cache.cuh, with the same capacity rule, so both make the same cells.
#include <cstddef>
#include <vector>

#include "pvr/photon/surface_cache.h"
#include "pvr/util/parallel_for.h"

namespace pvr {

// Slots for a frame of up to `points` gather points when the previous frame made `lastCells`
// cells: room at half load for every point up to 2^16 of them (so a small image never runs out),
// else for 4x the last frame's cells, at most 2^26 slots. Points whose cell finds no slot are
// estimated on their own; the next frame then grows.
uint32_t surfaceCacheCapacity(size_t points, size_t lastCells);

class HostSurfaceCache {
 public:
  // Empties the table for a new photon map: cells of side cellSize, `capacity` slots (a power of two).
  void reset(float cellSize, uint32_t capacity);
  // Adds the Lambertian points among `points` as a new pass (their cells, or new cells for them).
  void insert(const GatherPoint* points, size_t n);
  // Estimates the cells the last insert() created.
  template <class PhotonMap>
  void estimateCreated(const PhotonMap& map, const DensityParams& density) {
    const SurfaceCacheView cache = view();
    parallelFor("surface cache estimates", counters_[0], 16, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) estimateSurfaceCell(cache, map, cache.created[i], density);
    });
  }
  SurfaceCacheView view();
  bool empty() const { return keys_.empty(); }
  size_t cells() const { return counters_[1]; }
  size_t unplacedPoints() const { return counters_[2]; }  ///< points whose cell found no slot (all passes)
  uint32_t capacity() const { return uint32_t(keys_.size()); }
  size_t memoryBytes() const;

 private:
  std::vector<unsigned long long> keys_;
  std::vector<SurfaceCellSums> sums_;
  std::vector<SurfaceCellEstimate> estimates_;
  std::vector<uint32_t> created_;
  uint32_t counters_[3] = {0, 0, 0};
  uint32_t pass_ = 0;
  float cellSize_ = 1.0f;
};

}  // namespace pvr
