#pragma once
// View-independent density estimation: a hashed cache of surface cells, each holding one
// photon-map estimate that every pixel near it interpolates (of either eye and every sample of
// the frame), instead of one estimate per pixel. The idea is irradiance caching's (Ward 1988;
// Christensen 1999 for photon maps) on the hashed lattice of path-space filtering (Binder et al.
// 2019), applied to the main paper's estimate:
//  - a cell is a cube of side s (a fraction of the search radius) of a uniform lattice, keyed by
//    its integer coordinates and the dominant axis of the surface normal, so that the two walls
//    of a corner never share a cell;
//  - each Lambertian gather point adds its position and normal to its cell, in fixed point: the
//    sums do not depend on the order of the additions, so threads, the CPU and the GPU agree;
//  - each new cell is estimated once, at the centroid of its points with their mean normal, by
//    the same estimator and radius as a pixel (estimateFluxDensity);
//  - a pixel blends the estimates of the 8 cells around it (trilinear weights of the cell
//    centres), leaving out cells that are absent or lie off its tangent plane by over half a cell.
// The result is the per-pixel estimate taken up to a cell away and blurred over one more cell; it
// costs the visible surface area over s^2 estimates, not one per pixel. Microfacet gather points
// (view-dependent) are estimated per pixel, as is a point none of whose cells is usable.
// Insertion is written once over an `Atomics` policy (host: std::atomic_ref; device: atomicCAS).
#include <cstdint>

#include "pvr/photon/gather.h"

namespace pvr {

constexpr float kDefaultCacheCellFraction = 0.25f;  ///< cell side over the search radius
constexpr float kMinCacheCellFraction = 0.01f, kMaxCacheCellFraction = 1.0f;

constexpr uint64_t kNoSurfaceCell = ~uint64_t(0);  ///< an empty slot, or a point without a cell
constexpr int kCellCoordinateBits = 20;            ///< per axis, around the origin
constexpr int kCellCoordinateBias = 1 << (kCellCoordinateBits - 1);
constexpr int kCellFixedBits = 24;  ///< positions and normals are summed in units of 2^-24 (cells, unit normals)

// Which of the six axis directions the normal is nearest.
PVR_HOST_DEVICE inline uint32_t normalBucket(Vec3 n) {
  const float ax = fabsf(n.x), ay = fabsf(n.y), az = fabsf(n.z);
  const int axis = ax >= ay && ax >= az ? 0 : (ay >= az ? 1 : 2);
  return uint32_t(axis * 2) + (n[axis] < 0.0f ? 1u : 0u);
}

// The lattice cell holding p (floor of p / s per axis).
PVR_HOST_DEVICE inline void surfaceCellOf(Vec3 p, float invCellSize, int cell[3]) {
  for (int a = 0; a < 3; ++a) {
    const float f = floorf(p[a] * invCellSize);
    cell[a] = f >= -float(kCellCoordinateBias) && f < float(kCellCoordinateBias) ? int(f) : INT32_MIN;
  }
}

// The key of a cell and normal bucket: 20 bits per axis, 3 for the bucket; kNoSurfaceCell for a
// cell outside the lattice's range (INT32_MIN from surfaceCellOf, or NaN positions).
PVR_HOST_DEVICE inline uint64_t surfaceCellKey(const int cell[3], uint32_t bucket) {
  uint64_t key = bucket;
  for (int a = 0; a < 3; ++a) {
    const int64_t c = int64_t(cell[a]) + kCellCoordinateBias;
    if (c < 0 || c >= (int64_t(1) << kCellCoordinateBits)) return kNoSurfaceCell;
    key = (key << kCellCoordinateBits) | uint64_t(c);
  }
  return key;
}

PVR_HOST_DEVICE inline void cellOfSurfaceKey(uint64_t key, int cell[3]) {
  for (int a = 2; a >= 0; --a, key >>= kCellCoordinateBits)
    cell[a] = int(key & ((uint64_t(1) << kCellCoordinateBits) - 1)) - kCellCoordinateBias;
}

// What one gather point adds to its cell: its position from the cell's corner (in cells) and its
// normal, in fixed point (normals as two's complement).
struct SurfaceCellSums {
  unsigned long long position[3];
  unsigned long long normal[3];
  uint32_t count;
  uint32_t pass;  ///< the pass that created the cell; 0 while it is being created
};

PVR_HOST_DEVICE inline SurfaceCellSums surfacePointSums(Vec3 p, Vec3 n, const int cell[3], float invCellSize) {
  SurfaceCellSums s{};
  const float scale = float(1 << kCellFixedBits);
  for (int a = 0; a < 3; ++a) {
    float u = p[a] * invCellSize - float(cell[a]);
    u = u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
    s.position[a] = (unsigned long long)(u * scale);
    const float c = fmaxf(-1.0f, fminf(n[a], 1.0f));  // also maps a NaN component into range
    s.normal[a] = (unsigned long long)(long long)(c * scale);
  }
  s.count = 1;
  return s;
}

// A cell's estimate and where it was taken.
struct SurfaceCellEstimate {
  Vec3 point{0, 0, 0};
  Vec3 flux{0, 0, 0};  ///< estimateFluxDensity there
};

PVR_HOST_DEVICE inline uint32_t surfaceCellHash(uint64_t key) {  // splitmix64's finaliser
  key ^= key >> 30;
  key *= 0xbf58476d1ce4e5b9ull;
  key ^= key >> 27;
  key *= 0x94d049bb133111ebull;
  key ^= key >> 31;
  return uint32_t(key);
}

// The cache's table, open addressing with linear probing: `capacity` (a power of two) slots of
// key, sums and estimate. `created` lists the slots created in the current pass, their number in
// counters[0]; counters[1] counts the cells, counters[2] the points whose cell found no slot.
struct SurfaceCacheView {
  unsigned long long* keys = nullptr;
  SurfaceCellSums* sums = nullptr;
  SurfaceCellEstimate* estimates = nullptr;
  uint32_t* created = nullptr;
  uint32_t* counters = nullptr;
  uint32_t capacity = 0;
  uint32_t pass = 1;  ///< the pass being inserted (from 1)
  float cellSize = 1.0f, invCellSize = 1.0f;

  // The slot holding `key`, or -1 (read-only: after the pass's insertion).
  PVR_HOST_DEVICE int64_t find(uint64_t key) const {
    if (key == kNoSurfaceCell || capacity == 0) return -1;
    const uint32_t mask = capacity - 1;
    uint32_t slot = surfaceCellHash(key) & mask;
    for (uint32_t probe = 0; probe < capacity; ++probe, slot = (slot + 1) & mask) {
      const unsigned long long seen = keys[slot];
      if (seen == key) return slot;
      if (seen == kNoSurfaceCell) return -1;
    }
    return -1;
  }
};

// Whether a gather point takes its estimate from the cache: Lambertian points that need one.
PVR_HOST_DEVICE inline bool cachesEstimate(uint32_t lobes, Vec3 weight) { return lobes == 0 && !isBlack(weight); }

// The key of the cell a gather point adds to.
PVR_HOST_DEVICE inline uint64_t surfaceCellKeyOf(const SurfaceCacheView& cache, Vec3 position, Vec3 normal, int cell[3]) {
  surfaceCellOf(position, cache.invCellSize, cell);
  return surfaceCellKey(cell, normalBucket(normal));
}

// Finds or creates the slot of `key`; -1 if the table is full. `created` tells whether this call
// made it (the caller then lists it and stamps its pass).
template <class Atomics>
PVR_HOST_DEVICE int64_t findOrCreateSurfaceCell(const SurfaceCacheView& cache, uint64_t key, const Atomics& atomics,
                                                bool& created) {
  created = false;
  const uint32_t mask = cache.capacity - 1;
  uint32_t slot = surfaceCellHash(key) & mask;
  for (uint32_t probe = 0; probe < cache.capacity; ++probe, slot = (slot + 1) & mask) {
    unsigned long long seen = atomics.load64(&cache.keys[slot]);
    if (seen == kNoSurfaceCell) {
      seen = atomics.cas64(&cache.keys[slot], kNoSurfaceCell, key);
      if (seen == kNoSurfaceCell) {
        created = true;
        return slot;
      }
    }
    if (seen == key) return slot;
  }
  return -1;
}

// Adds `sums` (one point's, or several of one cell's) to the cell of `key`, unless an earlier
// pass created and estimated it; lists the cell if new. Counts a point without a slot.
template <class Atomics>
PVR_HOST_DEVICE void addToSurfaceCell(const SurfaceCacheView& cache, uint64_t key, const SurfaceCellSums& sums,
                                      const Atomics& atomics) {
  bool created = false;
  const int64_t slot = findOrCreateSurfaceCell(cache, key, atomics, created);
  if (slot < 0) {
    atomics.add32(&cache.counters[2], sums.count);
    return;
  }
  SurfaceCellSums& cell = cache.sums[slot];
  if (created) {
    cache.created[atomics.add32(&cache.counters[0], 1u)] = uint32_t(slot);
    atomics.add32(&cache.counters[1], 1u);
    atomics.store32(&cell.pass, cache.pass);
  } else {
    const uint32_t pass = atomics.load32(&cell.pass);
    if (pass != 0 && pass != cache.pass) return;  // estimated already: its value stays
  }
  for (int a = 0; a < 3; ++a) {
    atomics.add64(&cell.position[a], sums.position[a]);
    atomics.add64(&cell.normal[a], sums.normal[a]);
  }
  atomics.add32(&cell.count, sums.count);
}

// A cell's centroid and mean normal from its sums (exact integer sums, one rounding each).
PVR_HOST_DEVICE inline void surfaceCellPoint(const SurfaceCacheView& cache, uint32_t slot, Vec3& point, Vec3& normal) {
  const SurfaceCellSums& s = cache.sums[slot];
  int cell[3];
  cellOfSurfaceKey(cache.keys[slot], cell);
  const double perPoint = 1.0 / (double(s.count) * double(1 << kCellFixedBits));
  for (int a = 0; a < 3; ++a) {
    point[a] = float((double(cell[a]) + double(s.position[a]) * perPoint) * double(cache.cellSize));
    normal[a] = float(double((long long)s.normal[a]) * perPoint);
  }
  normal = normalize(normal);
}

// Estimates a cell created in this pass.
template <class PhotonMap>
PVR_HOST_DEVICE void estimateSurfaceCell(const SurfaceCacheView& cache, const PhotonMap& map, uint32_t slot,
                                         const DensityParams& density) {
  SurfaceCellEstimate e;
  Vec3 normal;
  surfaceCellPoint(cache, slot, e.point, normal);
  e.flux = estimateFluxDensity(map, e.point, normal, density);
  cache.estimates[slot] = e;
}

// The flux density at a surface point, blended from the cells around it; false if none is usable.
PVR_HOST_DEVICE inline bool cachedFluxDensity(const SurfaceCacheView& cache, Vec3 position, Vec3 normal, Vec3& flux) {
  const uint32_t bucket = normalBucket(normal);
  int base[3];
  float t[3];
  for (int a = 0; a < 3; ++a) {
    const float f = position[a] * cache.invCellSize - 0.5f;
    const float fl = floorf(f);
    base[a] = fl >= -float(kCellCoordinateBias) && fl < float(kCellCoordinateBias) ? int(fl) : INT32_MIN + 1;
    t[a] = f - fl;
  }
  if (base[0] == INT32_MIN + 1 || base[1] == INT32_MIN + 1 || base[2] == INT32_MIN + 1) return false;
  Vec3 sum{0, 0, 0};
  float weights = 0.0f;
  const float offPlane = 0.5f * cache.cellSize;
  for (int corner = 0; corner < 8; ++corner) {
    int cell[3];
    float w = 1.0f;
    for (int a = 0; a < 3; ++a) {
      const int bit = (corner >> a) & 1;
      cell[a] = base[a] + bit;
      w *= bit ? t[a] : 1.0f - t[a];
    }
    if (!(w > 0.0f)) continue;
    const int64_t slot = cache.find(surfaceCellKey(cell, bucket));
    if (slot < 0) continue;
    const SurfaceCellEstimate e = cache.estimates[slot];
    if (fabsf(dot(e.point - position, normal)) > offPlane) continue;
    sum += e.flux * w;
    weights += w;
  }
  if (!(weights > 0.0f)) return false;
  flux = sum * (1.0f / weights);
  return true;
}

// finishGather with the cache: the cached estimate where the point takes one and a cell is usable,
// else the point's own.
template <class PhotonMap>
PVR_HOST_DEVICE Vec3 finishGatherCached(const SurfaceCacheView& cache, const PhotonMap& map, const GatherPoint& point,
                                        const DensityParams& density) {
  Vec3 flux;
  if (cachesEstimate(point.lobes, point.weight) && cachedFluxDensity(cache, point.position, point.normal, flux))
    return point.radiance + point.weight * flux;
  return finishGather(map, point, density);
}

}  // namespace pvr
