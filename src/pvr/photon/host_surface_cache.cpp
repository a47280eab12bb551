#include "pvr/photon/host_surface_cache.h"

#include <algorithm>
#include <atomic>
#include <bit>

namespace pvr {
namespace {

struct HostAtomics {
  unsigned long long load64(unsigned long long* p) const {
    return std::atomic_ref<unsigned long long>(*p).load(std::memory_order_relaxed);
  }
  unsigned long long cas64(unsigned long long* p, unsigned long long expected, unsigned long long desired) const {
    std::atomic_ref<unsigned long long>(*p).compare_exchange_strong(expected, desired, std::memory_order_relaxed);
    return expected;  // the value seen: `expected` unchanged on success
  }
  void add64(unsigned long long* p, unsigned long long v) const {
    std::atomic_ref<unsigned long long>(*p).fetch_add(v, std::memory_order_relaxed);
  }
  uint32_t add32(uint32_t* p, uint32_t v) const { return std::atomic_ref<uint32_t>(*p).fetch_add(v, std::memory_order_relaxed); }
  uint32_t load32(uint32_t* p) const { return std::atomic_ref<uint32_t>(*p).load(std::memory_order_relaxed); }
  void store32(uint32_t* p, uint32_t v) const { std::atomic_ref<uint32_t>(*p).store(v, std::memory_order_relaxed); }
};

}  // namespace

uint32_t surfaceCacheCapacity(size_t points, size_t lastCells) {
  const size_t cells = std::max(std::min(points, size_t(1) << 16), 4 * lastCells);
  return uint32_t(std::min(std::bit_ceil(std::max<size_t>(2 * cells, 1024)), size_t(1) << 26));
}

void HostSurfaceCache::reset(float cellSize, uint32_t capacity) {
  keys_.assign(capacity, kNoSurfaceCell);
  sums_.assign(capacity, SurfaceCellSums{});
  estimates_.assign(capacity, SurfaceCellEstimate{});
  created_.assign(capacity, 0);
  counters_[0] = counters_[1] = counters_[2] = 0;
  pass_ = 0;
  cellSize_ = cellSize;
}

SurfaceCacheView HostSurfaceCache::view() {
  SurfaceCacheView v;
  v.keys = keys_.data();
  v.sums = sums_.data();
  v.estimates = estimates_.data();
  v.created = created_.data();
  v.counters = counters_;
  v.capacity = uint32_t(keys_.size());
  v.pass = pass_;
  v.cellSize = cellSize_;
  v.invCellSize = 1.0f / cellSize_;
  return v;
}

void HostSurfaceCache::insert(const GatherPoint* points, size_t n) {
  ++pass_;
  counters_[0] = 0;
  const SurfaceCacheView cache = view();
  parallelFor("surface cache insertion", n, 4096, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const GatherPoint& p = points[i];
      if (!cachesEstimate(p.lobes, p.weight)) continue;
      int cell[3];
      const uint64_t key = surfaceCellKeyOf(cache, p.position, p.normal, cell);
      if (key == kNoSurfaceCell) continue;
      addToSurfaceCell(cache, key, surfacePointSums(p.position, p.normal, cell, cache.invCellSize), HostAtomics());
    }
  });
}

size_t HostSurfaceCache::memoryBytes() const {
  return keys_.size() * (sizeof(unsigned long long) + sizeof(SurfaceCellSums) + sizeof(SurfaceCellEstimate) +
                         sizeof(uint32_t));
}

}  // namespace pvr
