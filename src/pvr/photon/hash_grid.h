#pragma once
// The hash-grid photon map of the main paper (section 3.1):
//  - the grid's origin is the photons' minimum corner, less one cell: one padding layer of cells
//    on every side, so that the 3x3x3 neighbourhood of any interior cell needs no bounds checks;
//  - cell side = search radius (enlarged by a relative 1e-3 or less, so that float rounding can
//    never put a photon within the radius two cells away from the query's cell);
//  - the linear hash of equation 2: z * dims.x * dims.y + y * dims.x + x;
//  - photons sorted by cell, `cellStart` the prefix sums of the cell counts (the paper's startIdx);
//  - a 9-entry offset table: the three cells x-1, x, x+1 of one row are contiguous in memory, so
//    each of the 9 (y, z) rows is one range cellStart[c - 1] .. cellStart[c + 2].
#include <vector>

#include "pvr/photon/photon.h"

namespace pvr {

// A photon's position padded to 16 bytes: the search loop reads it with one vector load.
struct alignas(16) PackedPosition {
  float x, y, z, pad;
};

struct HashGridView {
  const Photon* photons = nullptr;      ///< sorted by cell
  const PackedPosition* positions = nullptr;  ///< photons[i].position, for the search loop
  const uint32_t* cellStart = nullptr;  ///< cellCount + 1 entries
  uint32_t photonCount = 0;
  Vec3 origin;
  float cellSize = 1.0f;
  float invCellSize = 1.0f;
  int dims[3] = {3, 3, 3};  ///< cells per axis, padding included
  int rowOffsets[9] = {};   ///< from a cell to the x-1 cell of each of its 9 neighbouring rows

  PVR_HOST_DEVICE uint32_t hash(int x, int y, int z) const {  // equation 2
    return uint32_t(z) * uint32_t(dims[0]) * uint32_t(dims[1]) + uint32_t(y) * uint32_t(dims[0]) + uint32_t(x);
  }

  // Cell of a photon or query point, clamped into the interior; -1 if the point lies so far
  // outside the grid that no photon can be within one cell side of it (also for NaN).
  PVR_HOST_DEVICE int64_t cellOf(Vec3 p) const {
    int c[3];
    for (int a = 0; a < 3; ++a) {
      float f = (p[a] - origin[a]) * invCellSize;
      if (!(f >= 0.0f && f < float(dims[a]))) return -1;
      int i = int(f);
      c[a] = i < 1 ? 1 : (i > dims[a] - 2 ? dims[a] - 2 : i);
    }
    return int64_t(hash(c[0], c[1], c[2]));
  }

  PVR_HOST_DEVICE Vec3 position(uint32_t i) const {
#ifdef __CUDA_ARCH__
    float4 p = __ldg(reinterpret_cast<const float4*>(positions + i));
    return {p.x, p.y, p.z};
#else
    return {positions[i].x, positions[i].y, positions[i].z};
#endif
  }

  // Visits every photon with photonDistance2 <= r2, where r2 <= cellSize^2. `visit(index, d2, r2)`
  // may shrink r2 (kNN); the index is into `photons`.
  template <class Visitor>
  PVR_HOST_DEVICE void search(Vec3 q, float& r2, Visitor&& visit) const {
    if (photonCount == 0) return;
    int64_t center = cellOf(q);
    if (center < 0) return;
    for (int row = 0; row < 9; ++row) {
      uint32_t first = uint32_t(center + rowOffsets[row]);
      uint32_t end = cellStart[first + 3];
      for (uint32_t i = cellStart[first]; i < end; ++i) {
        float d2 = photonDistance2(q, position(i));
        if (d2 <= r2) visit(i, d2, r2);
      }
    }
  }

  // The same visits for searches that shrink r2 (kNN): the 9 rows nearest first (the query's own,
  // then those across its cell's nearer faces, then the farther ones), and a row, or its x-1 or
  // x+1 cell, skipped when its nearest point is farther than r2 has become. A skipped cell holds
  // no photon the visitor would still take, so the k nearest are the same as search's.
  template <class Visitor>
  PVR_HOST_DEVICE void searchNearest(Vec3 q, float& r2, Visitor&& visit) const {
    if (photonCount == 0) return;
    const int64_t center = cellOf(q);
    if (center < 0) return;
    const uint32_t c = uint32_t(center), slab = uint32_t(dims[0]) * uint32_t(dims[1]);
    float gxLo, gxHi, gyLo, gyHi, gzLo, gzHi;
    faceGaps(q.x, origin.x, int(c % uint32_t(dims[0])), gxLo, gxHi);
    faceGaps(q.y, origin.y, int((c / uint32_t(dims[0])) % uint32_t(dims[1])), gyLo, gyHi);
    faceGaps(q.z, origin.z, int(c / slab), gzLo, gzHi);
    const int ny = gyLo <= gyHi ? -1 : 1, nz = gzLo <= gzHi ? -1 : 1;  // the nearer neighbours
    const float gyNear2 = sq(fminf(gyLo, gyHi)), gyFar2 = sq(fmaxf(gyLo, gyHi));
    const float gzNear2 = sq(fminf(gzLo, gzHi)), gzFar2 = sq(fmaxf(gzLo, gzHi));
    const float gxLo2 = sq(gxLo), gxHi2 = sq(gxHi);
    // Row k's y and z neighbour, 2 bits each: 0 the query's own, 1 the nearer, 2 the farther.
    // Order (y, z): (0,0) (1,0) (0,1) (1,1) (2,0) (0,2) (1,2) (2,1) (2,2).
    constexpr uint32_t kRowY = 0b10'10'01'00'10'01'00'01'00u, kRowZ = 0b10'01'10'10'00'01'01'00'00u;
#ifdef __CUDA_ARCH__
#pragma unroll 1
#endif
    for (int row = 0; row < 9; ++row) {
      const uint32_t ySide = (kRowY >> (2 * row)) & 3u, zSide = (kRowZ >> (2 * row)) & 3u;
      const float rowGap2 = (ySide == 0 ? 0.0f : (ySide == 1 ? gyNear2 : gyFar2)) +
                            (zSide == 0 ? 0.0f : (zSide == 1 ? gzNear2 : gzFar2));
      if (rowGap2 > r2) continue;
      const int dy = ySide == 0 ? 0 : (ySide == 1 ? ny : -ny), dz = zSide == 0 ? 0 : (zSide == 1 ? nz : -nz);
      const uint32_t first = uint32_t(int64_t(c) + int64_t(dz) * slab + int64_t(dy) * dims[0] - 1);
      const uint32_t begin = cellStart[first + (rowGap2 + gxLo2 <= r2 ? 0 : 1)];
      const uint32_t end = cellStart[first + (rowGap2 + gxHi2 <= r2 ? 3 : 2)];
      for (uint32_t i = begin; i < end; ++i) {
        const float d2 = photonDistance2(q, position(i));
        if (d2 <= r2) visit(i, d2, r2);
      }
    }
  }

 private:
  PVR_HOST_DEVICE static float sq(float x) { return x * x; }

  // Distances from the coordinate x to the lower and upper faces of cell `cell` along one axis,
  // each lowered by a margin (a thousandth of a cell, plus the coordinate's float rounding) that
  // covers photons binned by cellOf's float arithmetic across a face; never negative.
  PVR_HOST_DEVICE void faceGaps(float x, float axisOrigin, int cell, float& lo, float& hi) const {
    const float f = (x - axisOrigin) * invCellSize;
    const float margin = 1e-3f + 1e-6f * fabsf(f);
    lo = fmaxf(0.0f, (f - float(cell) - margin) * cellSize);
    hi = fmaxf(0.0f, (float(cell + 1) - f - margin) * cellSize);
  }
};

// Host-side owner of a hash grid, built on the CPU with a stable counting sort by cell.
class HashGrid {
 public:
  // Throws pvr::Error if the radius is not positive and finite, or if the grid would need more
  // than kMaxCells cells (radius far too small for the photons' extent).
  static HashGrid build(const std::vector<Photon>& photons, float radius);
  static constexpr uint64_t kMaxCells = uint64_t(1) << 28;

  HashGridView view() const;
  const std::vector<Photon>& photons() const { return photons_; }
  const std::vector<uint32_t>& sortedToInput() const { return sortedToInput_; }
  const std::vector<uint32_t>& cellStart() const { return cellStart_; }
  float radius() const { return radius_; }
  size_t memoryBytes() const;

 private:
  std::vector<Photon> photons_;
  std::vector<PackedPosition> positions_;
  std::vector<uint32_t> cellStart_;
  std::vector<uint32_t> sortedToInput_;
  HashGridView layout_;  ///< geometry of the grid, pointers filled by view()
  float radius_ = 0;
};

// Grid geometry for a set of photon bounds and a radius (shared by the CPU and GPU builders).
HashGridView hashGridLayout(const Bounds3& photonBounds, float radius);

}  // namespace pvr
