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
