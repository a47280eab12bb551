#pragma once
// The balanced kd-tree photon map (Jensen; the main paper's baseline): a complete binary tree in
// an array (children of node i at 2i+1 and 2i+2, no pointers), each node splitting at the
// median photon along the longest axis of its photons' bounding box. Photons are ordered along
// an axis by (coordinate, input index), so the tree is unique: the CPU build (recursive, TBB) and
// the GPU build (level by level, cuda/photon_map_build.cu) make the same one.
#include <vector>

#include "pvr/photon/photon.h"

namespace pvr {

struct KdTreeView {
  const Photon* photons = nullptr;  ///< node i's photon
  const uint8_t* axes = nullptr;    ///< node i's split axis
  uint32_t photonCount = 0;

  static constexpr int kStackSize = 64;  ///< > depth of any tree of 2^32 nodes

  // For searches that shrink r2 (kNN): the tree's search already descends nearest first and
  // skips subtrees beyond r2.
  template <class Visitor>
  PVR_HOST_DEVICE void searchNearest(Vec3 q, float& r2, Visitor&& visit) const {
    search(q, r2, visit);
  }

  // Visits every photon with photonDistance2 <= r2; `visit(index, d2, r2)` may shrink r2.
  template <class Visitor>
  PVR_HOST_DEVICE void search(Vec3 q, float& r2, Visitor&& visit) const {
    uint32_t stackNode[kStackSize];
    float stackPlane2[kStackSize];
    int sp = 0;
    uint32_t node = 0;
    while (true) {
      while (node < photonCount) {
        const Vec3 p = photons[node].position;
        float d2 = photonDistance2(q, p);
        if (d2 <= r2) visit(node, d2, r2);
        int axis = axes[node];
        float delta = q[axis] - p[axis];
        uint32_t left = 2 * node + 1;
        uint32_t nearChild = delta > 0.0f ? left + 1 : left;
        uint32_t farChild = delta > 0.0f ? left : left + 1;
        if (farChild < photonCount && delta * delta <= r2) {
          stackNode[sp] = farChild;
          stackPlane2[sp] = delta * delta;
          ++sp;
        }
        node = nearChild;
      }
      do {
        if (sp == 0) return;
        --sp;
      } while (stackPlane2[sp] > r2);  // r2 may have shrunk since the push
      node = stackNode[sp];
    }
  }
};

class KdTree {
 public:
  static KdTree build(const std::vector<Photon>& photons);
  KdTreeView view() const { return {photons_.data(), axes_.data(), uint32_t(photons_.size())}; }
  const std::vector<Photon>& photons() const { return photons_; }
  const std::vector<uint32_t>& nodeToInput() const { return nodeToInput_; }
  size_t memoryBytes() const { return photons_.size() * (sizeof(Photon) + 1); }

 private:
  std::vector<Photon> photons_;
  std::vector<uint8_t> axes_;
  std::vector<uint32_t> nodeToInput_;
};

// The number of bits of n: the levels of a complete binary tree of n nodes.
PVR_HOST_DEVICE inline uint32_t bitWidth(uint32_t n) {
#ifdef __CUDA_ARCH__
  return 32u - uint32_t(__clz(n));
#else
  return n ? 32u - uint32_t(__builtin_clz(n)) : 0u;
#endif
}

// Size of the left subtree of a complete binary tree of n nodes.
PVR_HOST_DEVICE inline uint32_t completeTreeLeftSize(uint32_t n) {
  if (n <= 1) return 0;
  const uint32_t levels = bitWidth(n);             // depth of the last level + 1
  const uint32_t aboveLast = (1u << (levels - 1)) - 1;  // nodes in the full levels
  const uint32_t onLast = n - aboveLast;
  const uint32_t leftOnLast = onLast < (1u << (levels - 2)) ? onLast : (1u << (levels - 2));
  return (aboveLast - 1) / 2 + leftOnLast;
}

// Where slot `slot` of a build's order array (photons permuted so that every subtree's photons
// are contiguous, its median photon at its split) stands after the splits of the tree's first
// `levels` levels: the slot of a node's median photon (`placed`, at depth `depth` < levels), or a
// slot of the photons still to be split in node `node` at depth `levels`, slots [begin, end).
struct KdBuildSlot {
  uint32_t node = 0, begin = 0, end = 0;
  int depth = 0;
  bool placed = false;
};
PVR_HOST_DEVICE inline KdBuildSlot kdBuildSlot(uint32_t photonCount, uint32_t slot, int levels) {
  KdBuildSlot s;
  s.end = photonCount;
  for (; s.depth < levels; ++s.depth) {
    const uint32_t median = s.begin + completeTreeLeftSize(s.end - s.begin);
    if (slot == median) {
      s.placed = true;
      return s;
    }
    if (slot < median) s.end = median, s.node = 2 * s.node + 1;
    else s.begin = median + 1, s.node = 2 * s.node + 2;
  }
  return s;
}

// The level-by-level build's sort key of a slot at the level `s` was found for: a placed median
// keeps its slot; a photon still to split sorts into its node's slots by its rank along the
// node's axis (ranks by (coordinate, index), below 2^slotBits, as slots are).
PVR_HOST_DEVICE inline uint64_t kdSplitKey(const KdBuildSlot& s, uint32_t slot, uint32_t rankAlongAxis, int slotBits) {
  return s.placed ? uint64_t(slot) << slotBits : (uint64_t(s.begin) << slotBits) | rankAlongAxis;
}

}  // namespace pvr
