#pragma once
// The GPU's ray-tracing acceleration structure: an 8-wide BVH whose child boxes are quantized to
// 8 bits per plane on a grid anchored at the parent (the compressed wide BVH of Ylitie, Karras
// and Laine, HPG 2017). One 80-byte node (five 16-byte loads) decides 8 children, where the
// binary BVH (bvh.h) spends 64 bytes on 2: incoherent rays, which are bound by node fetches,
// visit fewer and smaller nodes. Built by Embree's rtcBuildBVH with a branching factor of 8 (SAH,
// spatial splits); the binary BVH stays for comparison (`bench --suite rays`).
//  - A node's inner children are consecutive nodes, in slot order, from `childBase`; its leaves'
//    triangles are consecutive from `triangleBase` (at most 3 per leaf, 24 per node).
//  - Slots are assigned by the children's direction from the node's centre (bit a of the slot:
//    the positive side of axis a), so that a ray visits them near to far by its direction's
//    signs alone, without sorting.
//  - Quantized boxes are conservative in the float arithmetic the traversal does: the
//    dequantized box fma(q, 2^e, origin) contains the child's box exactly.
#include <cstdint>
#include <vector>

#include "pvr/accel/bvh.h"

namespace pvr {

constexpr int kWideBvhWidth = 8;
constexpr unsigned kWideBvhMaxLeafSize = 3;
// The builder's depth limit in wide levels, and so the entries a traversal stack needs.
constexpr unsigned kWideBvhMaxDepth = 24;

struct alignas(16) WideBvhNode {
  float origin[3];        ///< the quantization grid's corner, at or below every child's lower corner
  int8_t exponent[3];     ///< grid step along axis a: 2^exponent[a]
  uint8_t innerMask;      ///< bit s: slot s holds an inner node
  uint32_t childBase;     ///< node index of the first inner child
  uint32_t triangleBase;  ///< index of the first triangle of this node's leaves
  // Slot s's leaf: (count << 5) | offset from triangleBase; 0 for an inner or empty slot.
  uint8_t leaf[8];
  uint8_t lower[3][8];  ///< slot s's box along axis a: [origin + lower[a][s] * step, origin + upper[a][s] * step]
  uint8_t upper[3][8];
};
static_assert(sizeof(WideBvhNode) == 80, "WideBvhNode must be 80 bytes");

struct WideBvhView {
  const WideBvhNode* nodes = nullptr;  ///< node 0 is the root
  const BvhTriangle* triangles = nullptr;
  uint32_t nodeCount = 0;  ///< 0: an empty scene
  uint32_t triangleCount = 0;
};

class WideBvh {
 public:
  // Builds over the scene's triangles; the primitive ids in hits are scene triangle indices.
  static WideBvh build(const Scene& scene);
  // Builds over raw triangles (3 vertices each); used by tests.
  static WideBvh build(const std::vector<Vec3>& vertices, const std::vector<uint32_t>& indices);

  WideBvhView view() const {
    return {nodes_.data(), triangles_.data(), uint32_t(nodes_.size()), uint32_t(triangles_.size())};
  }
  const std::vector<WideBvhNode>& nodes() const { return nodes_; }
  const std::vector<BvhTriangle>& triangles() const { return triangles_; }
  const BvhBuildStats& stats() const { return stats_; }
  size_t memoryBytes() const {
    return nodes_.size() * sizeof(WideBvhNode) + triangles_.size() * sizeof(BvhTriangle);
  }

 private:
  std::vector<WideBvhNode> nodes_;
  std::vector<BvhTriangle> triangles_;
  BvhBuildStats stats_;
};

}  // namespace pvr
