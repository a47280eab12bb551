#pragma once
// The balanced kd-tree photon map (Jensen; the main paper's baseline): a complete binary tree in
// an array (children of node i at 2i+1 and 2i+2, no pointers), each node splitting at the
// median photon along the longest axis of its photons' bounding box.
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

// Size of the left subtree of a complete binary tree of n nodes.
uint32_t completeTreeLeftSize(uint32_t n);

}  // namespace pvr
