#pragma once
// The GPU ray-tracing acceleration structure: a binary BVH built on the host by Embree's
// rtcBuildBVH (SAH, high quality, spatial splits), flattened into a layout for GPU traversal:
//  - a node holds both children's boxes (64 bytes, four 16-byte loads), so one fetch decides
//    which children a ray enters (Aila and Laine's layout);
//  - leaf triangles are stored in leaf order with their vertices inline (48 bytes, three 16-byte
//    loads), so a leaf test reads no index buffer. Spatial splits may reference a triangle from
//    several leaves.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pvr/math/vec.h"

namespace pvr {

class Scene;

// The builder's depth limit, and so the entries a traversal stack needs (one per level).
constexpr unsigned kBvhMaxDepth = 48;

struct alignas(16) BvhNode {
  // Child c's box: lower at bounds[6c .. 6c+2], upper at bounds[6c+3 .. 6c+5].
  float bounds[12];
  // >= 0: an inner node's index; < 0: a leaf whose first triangle is ~child[c].
  int32_t child[2];
  // Triangles in a leaf child (0 for an inner child, and for an empty child of a one-leaf tree).
  uint32_t count[2];
};
static_assert(sizeof(BvhNode) == 64, "BvhNode must be 64 bytes");

struct alignas(16) BvhTriangle {
  Vec3 v0;
  uint32_t primId;  ///< the scene's triangle index
  Vec3 v1;
  float pad1;
  Vec3 v2;
  float pad2;
};
static_assert(sizeof(BvhTriangle) == 48, "BvhTriangle must be 48 bytes");

struct BvhView {
  const BvhNode* nodes = nullptr;  ///< node 0 is the root
  const BvhTriangle* triangles = nullptr;
  uint32_t nodeCount = 0;
  uint32_t triangleCount = 0;  ///< triangle references, duplicates from spatial splits included
};

struct BvhBuildStats {
  double buildMs = 0;
  uint32_t inputTriangles = 0, triangleReferences = 0, nodes = 0, leaves = 0, maxDepth = 0;
  double sahCost = 0;  ///< expected cost per ray (traversal 1, triangle 1), relative to the root box
};

class Bvh {
 public:
  // Builds over the scene's triangles; the primitive ids in hits are scene triangle indices.
  static Bvh build(const Scene& scene);
  // Builds over raw triangles (3 vertices each); used by tests.
  static Bvh build(const std::vector<Vec3>& vertices, const std::vector<uint32_t>& indices);

  BvhView view() const {
    return {nodes_.data(), triangles_.data(), uint32_t(nodes_.size()), uint32_t(triangles_.size())};
  }
  const std::vector<BvhNode>& nodes() const { return nodes_; }
  const std::vector<BvhTriangle>& triangles() const { return triangles_; }
  const BvhBuildStats& stats() const { return stats_; }
  size_t memoryBytes() const { return nodes_.size() * sizeof(BvhNode) + triangles_.size() * sizeof(BvhTriangle); }

 private:
  std::vector<BvhNode> nodes_;
  std::vector<BvhTriangle> triangles_;
  BvhBuildStats stats_;
};

}  // namespace pvr
