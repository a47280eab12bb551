#include "pvr/photon/hash_grid.h"


#include <cfloat>
#include <cmath>
#include <cstdio>
#include <string>

#include "pvr/util/error.h"
#include "pvr/util/parallel_for.h"

namespace pvr {
namespace {
std::string formatNumber(float v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}
}  // namespace

HashGridView hashGridLayout(const Bounds3& bounds, float radius) {
  if (!(radius > 0.0f) || !std::isfinite(radius))
    throw Error("search radius must be a positive finite number, got " + formatNumber(radius));
  HashGridView g;
  Vec3 extent = bounds.empty() ? Vec3(0.0f) : bounds.extent();
  Vec3 lower = bounds.empty() ? Vec3(0.0f) : bounds.lower;
  // Enlarge the cell by more than the float rounding of (p - origin) / cell (a few ulps of the
  // cell count along an axis), so a photon within the radius is never two cells away.
  float cellsAlongAxis = maxComponent(extent) / radius + 3.0f;
  float margin = fmaxf(1.0f / 4096.0f, 16.0f * FLT_EPSILON * cellsAlongAxis);
  g.cellSize = radius * (1.0f + margin);
  g.invCellSize = 1.0f / g.cellSize;
  g.origin = lower - Vec3(g.cellSize);
  uint64_t cells = 1;
  for (int a = 0; a < 3; ++a) {
    double n = std::floor(double(extent[a]) / double(g.cellSize)) + 3.0;
    if (n > double(HashGrid::kMaxCells)) n = double(HashGrid::kMaxCells) + 1;
    g.dims[a] = int(n);
    cells *= uint64_t(n);
    if (cells > HashGrid::kMaxCells)
      throw Error("search radius " + formatNumber(radius) +
                  " is too small for the photons' extent: the hash grid would need more than " +
                  std::to_string(HashGrid::kMaxCells) + " cells");
  }
  int row = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy) g.rowOffsets[row++] = (dz * g.dims[1] + dy) * g.dims[0] - 1;
  return g;
}

HashGrid HashGrid::build(const std::vector<Photon>& input, float radius) {
  Bounds3 bounds;
  for (const Photon& p : input) bounds.extend(p.position);
  HashGrid grid;
  grid.radius_ = radius;
  grid.layout_ = hashGridLayout(bounds, radius);
  const HashGridView& g = grid.layout_;
  uint64_t cellCount = uint64_t(g.dims[0]) * g.dims[1] * g.dims[2];

  std::vector<uint32_t> keys(input.size());
  parallelFor("hash-grid cell keys", input.size(), 4096, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      int64_t c = g.cellOf(input[i].position);
      if (c < 0) throw Error("photon " + std::to_string(i) + " has a non-finite position");
      keys[i] = uint32_t(c);
    }
  });
  // Stable counting sort by cell: same order as a stable radix sort of (key, index) pairs.
  grid.cellStart_.assign(cellCount + 1, 0);
  for (uint32_t k : keys) ++grid.cellStart_[k + 1];
  for (uint64_t c = 0; c < cellCount; ++c) grid.cellStart_[c + 1] += grid.cellStart_[c];
  std::vector<uint32_t> cursor(grid.cellStart_.begin(), grid.cellStart_.end() - 1);
  grid.photons_.resize(input.size());
  grid.sortedToInput_.resize(input.size());
  for (uint32_t i = 0; i < input.size(); ++i) {
    uint32_t dst = cursor[keys[i]]++;
    grid.photons_[dst] = input[i];
    grid.sortedToInput_[dst] = i;
  }
  grid.positions_.resize(input.size());
  for (size_t i = 0; i < input.size(); ++i)
    grid.positions_[i] = {grid.photons_[i].position.x, grid.photons_[i].position.y, grid.photons_[i].position.z, 0.0f};
  return grid;
}

HashGridView HashGrid::view() const {
  HashGridView v = layout_;
  v.photons = photons_.data();
  v.positions = positions_.data();
  v.cellStart = cellStart_.data();
  v.photonCount = uint32_t(photons_.size());
  return v;
}

size_t HashGrid::memoryBytes() const {
  return photons_.size() * (sizeof(Photon) + sizeof(PackedPosition)) + cellStart_.size() * sizeof(uint32_t);
}

}  // namespace pvr
