#include <cub/device/device_radix_sort.cuh>

#include <algorithm>

#include "pvr/cuda/photon_map_build.cuh"

namespace pvr::cuda {
namespace {

__global__ void cellKeysKernel(HashGridView grid, const Photon* photons, uint32_t n, uint32_t* keys, uint32_t* values) {
  uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  int64_t c = grid.cellOf(photons[i].position);
  keys[i] = c < 0 ? 0u : uint32_t(c);  // bounds come from these photons: always inside
  values[i] = i;
}

// The first index at or after `from` whose key is not below `cell` (n if none), where every key
// before `from` is below it: one load where the cell is empty, a galloping search past full ones.
__device__ inline uint32_t firstKeyNotBelow(const uint32_t* keys, uint32_t n, uint32_t from, uint64_t cell) {
  if (from >= n || keys[from] >= cell) return from;
  uint32_t below = from, above = n;  // keys[below] < cell <= keys[above] (or above == n)
  for (uint64_t step = 1;; step <<= 1) {
    const uint64_t probe = uint64_t(below) + step;
    if (probe >= n) break;
    if (keys[probe] >= cell) {
      above = uint32_t(probe);
      break;
    }
    below = uint32_t(probe);
  }
  uint32_t lo = below + 1, hi = above;
  while (lo < hi) {
    const uint32_t mid = lo + (hi - lo) / 2;
    if (keys[mid] < cell) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

// startIdx from the sorted keys: cellStart[c] = the first photon of cell c or after it, for
// c = 0..cells. A warp takes 32 x perLane consecutive cells, lane l every 32nd from l (the stores
// coalesce), each search starting where the lane's last one ended. It writes 4 bytes a cell where
// counting and scanning the counts moved 12, which is the build's cost when the photons spread
// over tens of millions of mostly empty cells (Sibenik's surroundings: 0.46 -> 0.28 ms, H100).
// Where cells are few, a lane per cell keeps the GPU busy (16 a lane: 0.25 -> 0.37 ms for 1 M
// photons in 11 k cells).
__global__ void cellStartsKernel(const uint32_t* sortedKeys, uint32_t n, uint64_t cells, int perLane, uint32_t* cellStart) {
  const uint64_t thread = uint64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  const uint64_t base = (thread / 32) * 32 * uint64_t(perLane) + thread % 32;
  uint32_t at = 0;
  for (int j = 0; j < perLane; ++j) {
    const uint64_t cell = base + uint64_t(j) * 32;
    if (cell > cells) return;
    at = firstKeyNotBelow(sortedKeys, n, at, cell);
    cellStart[cell] = at;
  }
}

__global__ void gatherPhotonsKernel(const Photon* photons, const uint32_t* order, uint32_t n, Photon* sorted,
                                    PackedPosition* positions) {
  uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  Photon p = photons[order[i]];
  sorted[i] = p;
  positions[i] = {p.position.x, p.position.y, p.position.z, 0.0f};
}


// The kd-tree build (GpuKdTree::build).

__global__ void kdRankKeysKernel(const Photon* photons, uint32_t n, int axis, uint32_t* keys, uint32_t* values) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  keys[i] = orderedBits(photons[i].position[axis]);
  values[i] = i;  // the sort is stable: equal coordinates stay in index order
}

__global__ void kdRanksKernel(const uint32_t* sorted, uint32_t n, uint32_t* ranks) {
  const uint32_t r = blockIdx.x * blockDim.x + threadIdx.x;
  if (r < n) ranks[sorted[r]] = r;
}

__global__ void kdIdentityKernel(uint32_t* slots, uint32_t n) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) slots[i] = i;
}

struct KdBuildArrays {
  const Photon* photons;
  uint32_t count;
  const uint32_t* ranks;  ///< [axis * rankStride + photon]
  uint32_t rankStride;
  uint32_t *lower, *upper;  ///< node bounds as orderedBits, [node * 3 + axis]
  uint8_t* axes;
  Photon* treePhotons;
  uint32_t* nodeToInput;
  int slotBits;
};

__device__ inline Bounds3 kdNodeBounds(const KdBuildArrays& a, uint32_t node) {
  Bounds3 b;
  for (int k = 0; k < 3; ++k) {
    b.lower[k] = fromOrderedBits(a.lower[node * 3 + k]);
    b.upper[k] = fromOrderedBits(a.upper[node * 3 + k]);
  }
  return b;
}

// Slot by slot: a median placed at the level above becomes its node's photon; a photon still to
// split adds its position to its node's bounds (one atomic per warp where the whole warp is one
// node, as at the upper levels).
__global__ void kdBoundsKernel(KdBuildArrays a, const uint32_t* slots, int level) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  uint32_t node = ~0u;
  Vec3 p{0, 0, 0};
  if (i < a.count) {
    const KdBuildSlot s = kdBuildSlot(a.count, i, level);
    const uint32_t photon = slots[i];
    if (s.placed) {
      if (s.depth == level - 1) {
        a.treePhotons[s.node] = a.photons[photon];
        a.nodeToInput[s.node] = photon;
      }
    } else {
      node = s.node;
      p = a.photons[photon].position;
    }
  }
  const unsigned peers = __match_any_sync(0xffffffffu, node);
  if (node == ~0u) return;
  Vec3 lo = p, hi = p;
  if (peers == 0xffffffffu) {
    for (int offset = 16; offset > 0; offset >>= 1)
      for (int k = 0; k < 3; ++k) {
        lo[k] = fminf(lo[k], __shfl_xor_sync(0xffffffffu, lo[k], offset));
        hi[k] = fmaxf(hi[k], __shfl_xor_sync(0xffffffffu, hi[k], offset));
      }
    if ((threadIdx.x & 31u) != 0) return;
  }
  for (int k = 0; k < 3; ++k) {
    atomicMin(a.lower + node * 3 + k, orderedBits(lo[k]));
    atomicMax(a.upper + node * 3 + k, orderedBits(hi[k]));
  }
}

// Slot by slot: the key that sorts each node's photons into its slots by rank along the node's
// longest axis (the CPU's nth_element order), and keeps placed medians where they are.
__global__ void kdSplitKeysKernel(KdBuildArrays a, const uint32_t* slots, int level, uint64_t* keys) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= a.count) return;
  const KdBuildSlot s = kdBuildSlot(a.count, i, level);
  uint32_t rank = 0;
  if (!s.placed) {
    const int axis = kdNodeBounds(a, s.node).longestAxis();
    if (i == s.begin) a.axes[s.node] = uint8_t(axis);
    rank = a.ranks[size_t(axis) * a.rankStride + slots[i]];
  }
  keys[i] = kdSplitKey(s, i, rank, a.slotBits);
}

}  // namespace

size_t GpuHashGrid::memoryBytes() const {
  return keys_[0].bytes() + keys_[1].bytes() + values_[0].bytes() + values_[1].bytes() +
         cellStart_.bytes() + sorted_.bytes() + positions_.bytes() + temp_.bytes();
}

void GpuHashGrid::build(const Photon* photons, uint32_t count, const Bounds3& bounds, float radius,
                        cudaStream_t stream) {
  view_ = hashGridLayout(bounds, radius);  // the CPU builder's layout: same cells, same order
  cellCount_ = uint64_t(view_.dims[0]) * view_.dims[1] * view_.dims[2];
  size_t n = std::max<size_t>(count, 1);
  for (int b = 0; b < 2; ++b) {
    keys_[b].reserve(n, "hash-grid keys");
    values_[b].reserve(n, "hash-grid permutation");
  }
  cellStart_.reserve(cellCount_ + 1, "hash-grid startIdx");
  sorted_.reserve(n, "hash-grid photons");
  positions_.reserve(n, "hash-grid positions");
  int endBit = radixBitsFor(cellCount_);
  cub::DoubleBuffer<uint32_t> keys(keys_[0].data(), keys_[1].data()), values(values_[0].data(), values_[1].data());
  size_t sortBytes = 0;
  PVR_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, sortBytes, keys, values, int(n), 0, endBit, stream));
  temp_.reserve(sortBytes, "hash-grid sort scratch");
  if (count) {
    launch("hash-grid cell keys", cellKeysKernel, blocksFor(count, 256), 256, 0, stream, view_, photons, count,
           keys_[0].data(), values_[0].data());
    size_t bytes = temp_.capacity();
    PVR_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp_.data(), bytes, keys, values, int(count), 0, endBit, stream));
    sortedBuffer_ = keys.selector;
    launch("hash-grid photons in cell order", gatherPhotonsKernel, blocksFor(count, 256), 256, 0, stream, photons,
           values.Current(), count, sorted_.data(), positions_.data());
  }
  const int perLane = cellCount_ + 1 > 4 * uint64_t(n) ? 16 : 1;  // mostly empty cells: a lane walks several
  const uint64_t lanes = (cellCount_ + 1 + perLane - 1) / perLane;
  launch("hash-grid startIdx", cellStartsKernel, unsigned((lanes + 255) / 256), 256, 0, stream,
         count ? keys.Current() : keys_[0].data(), count, cellCount_, perLane, cellStart_.data());
  view_.photons = sorted_.data();
  view_.positions = positions_.data();
  view_.cellStart = cellStart_.data();
  view_.photonCount = count;
}

void GpuHashGrid::download(std::vector<Photon>& photons, std::vector<uint32_t>& cellStart,
                           std::vector<uint32_t>& sortedToInput) const {
  photons.resize(view_.photonCount);
  sortedToInput.resize(view_.photonCount);
  cellStart.resize(cellCount_ + 1);
  sorted_.download(photons.data(), photons.size());
  values_[sortedBuffer_].download(sortedToInput.data(), sortedToInput.size());
  cellStart_.download(cellStart.data(), cellStart.size());
}

size_t GpuKdTree::memoryBytes() const {
  return photons_.bytes() + axes_.bytes() + nodeToInput_.bytes() + ranks_.bytes() + order_[0].bytes() +
         order_[1].bytes() + boundsLower_.bytes() + boundsUpper_.bytes() + keys_[0].bytes() + keys_[1].bytes() +
         temp_.bytes();
}

void GpuKdTree::build(const Photon* photons, uint32_t count, cudaStream_t stream) {
  const size_t n = std::max<size_t>(count, 1);
  photons_.reserve(n, "kd-tree photons");
  axes_.reserve(n, "kd-tree axes");
  nodeToInput_.reserve(n, "kd-tree node order");
  ranks_.reserve(3 * n, "kd-tree ranks");
  boundsLower_.reserve(3 * n, "kd-tree node bounds");
  boundsUpper_.reserve(3 * n, "kd-tree node bounds");
  for (int b = 0; b < 2; ++b) {
    order_[b].reserve(n, "kd-tree slots");
    keys_[b].reserve(n, "kd-tree sort keys");
  }
  // The rank sorts use the first half of each key buffer as 32-bit keys.
  uint32_t* rankKeys[2] = {reinterpret_cast<uint32_t*>(keys_[0].data()), reinterpret_cast<uint32_t*>(keys_[1].data())};
  cub::DoubleBuffer<uint32_t> rankKeyBuffer(rankKeys[0], rankKeys[1]), rankValues(order_[0].data(), order_[1].data());
  cub::DoubleBuffer<uint64_t> slotKeys(keys_[0].data(), keys_[1].data());
  cub::DoubleBuffer<uint32_t> slotValues(order_[0].data(), order_[1].data());
  const int slotBits = int(bitWidth(uint32_t(n - 1)));
  size_t rankBytes = 0, slotBytes = 0;
  PVR_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, rankBytes, rankKeyBuffer, rankValues, int(n), 0, 32, stream));
  PVR_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, slotBytes, slotKeys, slotValues, int(n), 0,
                                                 std::max(2 * slotBits, 1), stream));
  temp_.reserve(std::max(rankBytes, slotBytes), "kd-tree sort scratch");
  view_ = {photons_.data(), axes_.data(), count};
  if (count == 0) return;

  for (int axis = 0; axis < 3; ++axis) {
    launch("kd-tree rank keys", kdRankKeysKernel, blocksFor(count, 256), 256, 0, stream, photons, count, axis,
           rankKeyBuffer.Current(), rankValues.Current());
    size_t bytes = temp_.capacity();
    PVR_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp_.data(), bytes, rankKeyBuffer, rankValues, int(count), 0, 32, stream));
    launch("kd-tree ranks", kdRanksKernel, blocksFor(count, 256), 256, 0, stream, rankValues.Current(), count,
           ranks_.data() + size_t(axis) * n);
  }
  PVR_CUDA_CHECK(cudaMemsetAsync(boundsLower_.data(), 0xff, 3 * n * sizeof(uint32_t), stream));
  PVR_CUDA_CHECK(cudaMemsetAsync(boundsUpper_.data(), 0, 3 * n * sizeof(uint32_t), stream));
  launch("kd-tree slots", kdIdentityKernel, blocksFor(count, 256), 256, 0, stream, slotValues.Current(), count);
  KdBuildArrays a;
  a.photons = photons;
  a.count = count;
  a.ranks = ranks_.data();
  a.rankStride = uint32_t(n);
  a.lower = boundsLower_.data();
  a.upper = boundsUpper_.data();
  a.axes = axes_.data();
  a.treePhotons = photons_.data();
  a.nodeToInput = nodeToInput_.data();
  a.slotBits = slotBits;
  const int levels = int(bitWidth(count));
  for (int level = 0; level <= levels; ++level) {
    // Places the medians of the level above and bounds the photons still to split at this one.
    launch("kd-tree bounds", kdBoundsKernel, blocksFor(count, 256), 256, 0, stream, a, slotValues.Current(), level);
    if (level == levels) break;
    launch("kd-tree split keys", kdSplitKeysKernel, blocksFor(count, 256), 256, 0, stream, a, slotValues.Current(), level,
           slotKeys.Current());
    if (level + 1 == levels) continue;  // the last level's nodes are leaves: one photon each, in place
    size_t bytes = temp_.capacity();
    PVR_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp_.data(), bytes, slotKeys, slotValues, int(count), 0,
                                                   std::max(2 * slotBits, 1), stream));
  }
}

void GpuKdTree::download(std::vector<Photon>& photons, std::vector<uint8_t>& axes, std::vector<uint32_t>& nodeToInput) const {
  const uint32_t n = view_.photonCount;
  photons.resize(n);
  axes.resize(n);
  nodeToInput.resize(n);
  photons_.download(photons.data(), n);
  axes_.download(axes.data(), n);
  nodeToInput_.download(nodeToInput.data(), n);
}

}  // namespace pvr::cuda
