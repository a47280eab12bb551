#include "pvr/accel/bvh.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>

#include "pvr/accel/bvh_traversal.h"
#include "pvr/accel/wide_bvh.h"
#include "pvr/accel/wide_bvh_traversal.h"

#include "pvr/scene/scene.h"
#include "pvr/util/error.h"
#include "pvr/util/parallel_for.h"

namespace pvr {
namespace {

// Embree's builder calls back into these while building in parallel; nodes live in its
// thread-local allocator until the BVH is released, after we have flattened them.
struct BuildNode {
  bool leaf;
};
struct BuildInner : BuildNode {
  unsigned childCount;
  BuildNode* children[kWideBvhWidth];
  Bounds3 bounds[kWideBvhWidth];
};
struct BuildLeaf : BuildNode {
  uint32_t count;
  uint32_t prims[1];  // `count` entries, allocated in place
};

struct BuildInput {
  const std::vector<Vec3>* vertices;
  const std::vector<uint32_t>* indices;
};

constexpr unsigned kMaxLeafSize = 4;

// A leaf's copy of input triangle `prim`, vertices inline.
BvhTriangle leafTriangle(const BuildInput& in, uint32_t prim) {
  BvhTriangle t{};
  t.v0 = (*in.vertices)[(*in.indices)[3 * size_t(prim)]];
  t.v1 = (*in.vertices)[(*in.indices)[3 * size_t(prim) + 1]];
  t.v2 = (*in.vertices)[(*in.indices)[3 * size_t(prim) + 2]];
  t.primId = prim;
  return t;
}

void* createInner(RTCThreadLocalAllocator alloc, unsigned int childCount, void*) {
  auto* node = static_cast<BuildInner*>(rtcThreadLocalAlloc(alloc, sizeof(BuildInner), 16));
  node->leaf = false;
  node->childCount = 0;
  for (BuildNode*& c : node->children) c = nullptr;
  return node;
}

void setChildren(void* nodePtr, void** children, unsigned int childCount, void*) {
  auto* node = static_cast<BuildInner*>(nodePtr);
  node->childCount = std::min(childCount, unsigned(kWideBvhWidth));
  for (unsigned i = 0; i < node->childCount; ++i) node->children[i] = static_cast<BuildNode*>(children[i]);
}

void setBounds(void* nodePtr, const RTCBounds** bounds, unsigned int childCount, void*) {
  auto* node = static_cast<BuildInner*>(nodePtr);
  for (unsigned i = 0; i < childCount && i < unsigned(kWideBvhWidth); ++i) {
    node->bounds[i].lower = {bounds[i]->lower_x, bounds[i]->lower_y, bounds[i]->lower_z};
    node->bounds[i].upper = {bounds[i]->upper_x, bounds[i]->upper_y, bounds[i]->upper_z};
  }
}

void* createLeaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void*) {
  size_t bytes = sizeof(BuildLeaf) + sizeof(uint32_t) * (count > 0 ? count - 1 : 0);
  auto* leaf = static_cast<BuildLeaf*>(rtcThreadLocalAlloc(alloc, bytes, 16));
  leaf->leaf = true;
  leaf->count = uint32_t(count);
  for (size_t i = 0; i < count; ++i) leaf->prims[i] = prims[i].primID;
  return leaf;
}

// Spatial split: the bounds of the two parts of the triangle clipped at `position` along
// `dimension`, within the reference's current (possibly already clipped) bounds.
void splitPrimitive(const RTCBuildPrimitive* prim, unsigned int dimension, float position, RTCBounds* leftOut,
                    RTCBounds* rightOut, void* userPtr) {
  const auto& in = *static_cast<const BuildInput*>(userPtr);
  Vec3 v[3];
  for (int k = 0; k < 3; ++k) v[k] = (*in.vertices)[(*in.indices)[3 * size_t(prim->primID) + k]];
  Bounds3 left, right;
  int d = int(dimension);
  for (int k = 0; k < 3; ++k) {
    Vec3 a = v[k], b = v[(k + 1) % 3];
    if (a[d] <= position) left.extend(a);
    if (a[d] >= position) right.extend(a);
    if ((a[d] < position && b[d] > position) || (a[d] > position && b[d] < position)) {
      float t = (position - a[d]) / (b[d] - a[d]);
      Vec3 p = a + (b - a) * std::clamp(t, 0.0f, 1.0f);
      p[d] = position;
      left.extend(p);
      right.extend(p);
    }
  }
  Bounds3 current{{prim->lower_x, prim->lower_y, prim->lower_z}, {prim->upper_x, prim->upper_y, prim->upper_z}};
  auto clip = [&](Bounds3 b, RTCBounds* out) {
    b.lower = max(b.lower, current.lower);
    b.upper = min(b.upper, current.upper);
    out->lower_x = b.lower.x, out->lower_y = b.lower.y, out->lower_z = b.lower.z;
    out->upper_x = b.upper.x, out->upper_y = b.upper.y, out->upper_z = b.upper.z;
  };
  left.upper[d] = fminf(left.upper[d], position);
  right.lower[d] = fmaxf(right.lower[d], position);
  clip(left, leftOut);
  clip(right, rightOut);
}

float surfaceArea(const Bounds3& b) {
  if (b.empty()) return 0.0f;
  Vec3 e = b.extent();
  return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
}

class Flattener {
 public:
  Flattener(const BuildInput& in, std::vector<BvhNode>& nodes, std::vector<BvhTriangle>& tris, BvhBuildStats& stats)
      : in_(in), nodes_(nodes), tris_(tris), stats_(stats) {}

  void flattenRoot(const BuildNode* root, const Bounds3& rootBounds) {
    rootArea_ = std::max(surfaceArea(rootBounds), 1e-30f);
    nodes_.push_back({});
    if (!root || root->leaf) {  // a one-leaf tree: the root's second child is empty
      setChild(0, 0, root, rootBounds, 1);
      setEmpty(0, 1);
      stats_.sahCost = 1.0 + (root ? static_cast<const BuildLeaf*>(root)->count : 0);
    } else {
      stats_.sahCost = 1.0;
      fillInner(0, static_cast<const BuildInner*>(root), 1);
    }
  }

 private:
  void fillInner(uint32_t index, const BuildInner* node, uint32_t depth) {
    stats_.maxDepth = std::max(stats_.maxDepth, depth);
    // A traversal pushes at most one entry per inner node on its path; its stack has no bound check.
    if (depth > uint32_t(BvhIntersector::kStackSize))
      throw Error("the BVH is deeper than its traversal stack: " + std::to_string(depth));
    for (int c = 0; c < 2; ++c) {
      if (node->children[c]) setChild(index, c, node->children[c], node->bounds[c], depth + 1);
      else setEmpty(index, c);
    }
  }

  void setChild(uint32_t index, int c, const BuildNode* child, const Bounds3& b, uint32_t depth) {
    for (int a = 0; a < 3; ++a) {
      nodes_[index].bounds[6 * c + a] = b.lower[a];
      nodes_[index].bounds[6 * c + 3 + a] = b.upper[a];
    }
    double relArea = surfaceArea(b) / rootArea_;
    if (child->leaf) {
      const auto* leaf = static_cast<const BuildLeaf*>(child);
      nodes_[index].child[c] = ~int32_t(tris_.size());
      nodes_[index].count[c] = leaf->count;
      for (uint32_t i = 0; i < leaf->count; ++i) tris_.push_back(leafTriangle(in_, leaf->prims[i]));
      stats_.leaves++;
      stats_.sahCost += relArea * leaf->count;
      stats_.maxDepth = std::max(stats_.maxDepth, depth);
    } else {
      uint32_t childIndex = uint32_t(nodes_.size());
      nodes_.push_back({});
      nodes_[index].child[c] = int32_t(childIndex);
      nodes_[index].count[c] = 0;
      stats_.sahCost += relArea;
      fillInner(childIndex, static_cast<const BuildInner*>(child), depth);
    }
  }

  void setEmpty(uint32_t index, int c) {
    for (int a = 0; a < 3; ++a) {
      nodes_[index].bounds[6 * c + a] = INFINITY;
      nodes_[index].bounds[6 * c + 3 + a] = -INFINITY;
    }
    nodes_[index].child[c] = ~0;
    nodes_[index].count[c] = 0;
  }

  const BuildInput& in_;
  std::vector<BvhNode>& nodes_;
  std::vector<BvhTriangle>& tris_;
  BvhBuildStats& stats_;
  double rootArea_ = 1.0;
};

// Runs Embree's builder over the triangles and hands its tree (null when no triangle is finite)
// and the root's box to `flatten` while the tree is alive.
template <class Flatten>
void buildWithEmbree(const BuildInput& input, unsigned branching, unsigned maxLeafSize, unsigned maxDepth,
                     Flatten&& flatten) {
  const std::vector<Vec3>& vertices = *input.vertices;
  const std::vector<uint32_t>& indices = *input.indices;
  size_t triangleCount = indices.size() / 3;
  if (triangleCount >= (size_t(1) << 30)) throw Error("too many triangles for the GPU BVH: " + std::to_string(triangleCount));
  // Spatial splits need room for the references they add.
  std::vector<RTCBuildPrimitive> prims(std::max<size_t>(2 * triangleCount, 1));
  Bounds3 rootBounds;
  size_t count = 0;
  for (size_t i = 0; i < triangleCount; ++i) {
    Bounds3 b;
    for (int k = 0; k < 3; ++k) b.extend(vertices[indices[3 * i + k]]);
    if (!isFinite(b.lower) || !isFinite(b.upper)) continue;  // the scene drops these; raw input may not
    RTCBuildPrimitive& p = prims[count++];
    p.lower_x = b.lower.x, p.lower_y = b.lower.y, p.lower_z = b.lower.z;
    p.upper_x = b.upper.x, p.upper_y = b.upper.y, p.upper_z = b.upper.z;
    p.geomID = 0;
    p.primID = unsigned(i);
    rootBounds.extend(b.lower);
    rootBounds.extend(b.upper);
  }
  if (count == 0) {
    flatten(static_cast<const BuildNode*>(nullptr), rootBounds);
    return;
  }
  const int threads = libraryThreadLimit();
  RTCDevice device = rtcNewDevice(threads ? ("threads=" + std::to_string(threads)).c_str() : nullptr);
  if (!device) throw Error("Embree: cannot create a device for the BVH build");
  RTCBVH handle = rtcNewBVH(device);
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.byteSize = sizeof(args);
  args.buildQuality = RTC_BUILD_QUALITY_HIGH;  // SAH with spatial splits
  args.buildFlags = RTC_BUILD_FLAG_NONE;
  args.maxBranchingFactor = branching;
  args.maxDepth = maxDepth;
  args.sahBlockSize = 1;
  args.minLeafSize = 1;
  args.maxLeafSize = maxLeafSize;
  args.traversalCost = 1.0f;
  args.intersectionCost = 1.0f;
  args.bvh = handle;
  args.primitives = prims.data();
  args.primitiveCount = count;
  args.primitiveArrayCapacity = prims.size();
  args.createNode = createInner;
  args.setNodeChildren = setChildren;
  args.setNodeBounds = setBounds;
  args.createLeaf = createLeaf;
  args.splitPrimitive = splitPrimitive;
  args.userPtr = const_cast<BuildInput*>(&input);
  auto* root = static_cast<BuildNode*>(rtcBuildBVH(&args));
  RTCError error = rtcGetDeviceError(device);
  if (!root || error != RTC_ERROR_NONE) {
    rtcReleaseBVH(handle);
    rtcReleaseDevice(device);
    throw Error("Embree: the BVH build failed (error " + std::to_string(int(error)) + ")");
  }
  try {
    flatten(static_cast<const BuildNode*>(root), rootBounds);
  } catch (...) {
    rtcReleaseBVH(handle);
    rtcReleaseDevice(device);
    throw;
  }
  rtcReleaseBVH(handle);
  rtcReleaseDevice(device);
}

// Flattens Embree's 8-wide tree into quantized nodes (wide_bvh.h).
class WideBvhFlattener {
 public:
  WideBvhFlattener(const BuildInput& in, std::vector<WideBvhNode>& nodes, std::vector<BvhTriangle>& tris, BvhBuildStats& stats)
      : in_(in), nodes_(nodes), triangles_(tris), stats_(stats) {}

  void flattenRoot(const BuildNode* root, const Bounds3& rootBounds) {
    if (!root) return;  // no triangle: no node, and every ray misses
    rootArea_ = std::max(surfaceArea(rootBounds), 1e-30f);
    nodes_.push_back({});
    std::vector<Child> children;
    if (root->leaf) {
      children.push_back({root, rootBounds});
    } else {
      const auto* inner = static_cast<const BuildInner*>(root);
      for (unsigned c = 0; c < inner->childCount; ++c) children.push_back({inner->children[c], inner->bounds[c]});
    }
    stats_.sahCost = 1.0;
    fill(0, children, 1);
  }

 private:
  struct Child {
    const BuildNode* node;
    Bounds3 bounds;
  };

  void fill(uint32_t index, const std::vector<Child>& children, uint32_t depth) {
    BvhBuildStats& stats = stats_;
    stats.maxDepth = std::max(stats.maxDepth, depth);
    if (depth > kWideBvhMaxDepth) throw Error("the wide BVH is deeper than its traversal stack: " + std::to_string(depth));
    const std::array<int, kWideBvhWidth> slotOf = assignSlots(children);
    std::array<int, kWideBvhWidth> childInSlot;
    childInSlot.fill(-1);
    for (size_t i = 0; i < children.size(); ++i) childInSlot[size_t(slotOf[i])] = int(i);

    WideBvhNode node{};
    Bounds3 box;
    for (const Child& c : children) {
      box.extend(c.bounds.lower);
      box.extend(c.bounds.upper);
    }
    for (int a = 0; a < 3; ++a) {
      const float lo = box.lower[a], hi = box.upper[a];
      node.origin[a] = lo;
      int e = -100;
      if (hi > lo) e = std::clamp(int(std::ceil(std::log2(double(hi - lo) / 255.0))), -100, 100);
      while (e < 100 && wideBvhPlane(255, wideBvhStep(e), lo) < hi) ++e;
      node.exponent[a] = int8_t(e);
    }
    // Slots in order: inner children become consecutive nodes, leaves' triangles consecutive.
    std::vector<std::pair<int, const BuildInner*>> inner;  // (slot, node)
    node.childBase = uint32_t(nodes_.size());
    node.triangleBase = uint32_t(triangles_.size());
    for (int s = 0; s < kWideBvhWidth; ++s) {
      if (childInSlot[size_t(s)] < 0) continue;  // empty: no leaf count, not inner
      const Child& c = children[size_t(childInSlot[size_t(s)])];
      quantize(node, s, c.bounds);
      const double relArea = surfaceArea(c.bounds) / rootArea_;
      if (c.node->leaf) {
        const auto* leaf = static_cast<const BuildLeaf*>(c.node);
        const uint32_t offset = uint32_t(triangles_.size()) - node.triangleBase;
        if (leaf->count == 0 || leaf->count > kWideBvhMaxLeafSize || offset + leaf->count > 24)
          throw Error("wide BVH: a leaf of " + std::to_string(leaf->count) + " triangles cannot be encoded");
        node.leaf[s] = uint8_t((leaf->count << 5) | offset);
        for (uint32_t i = 0; i < leaf->count; ++i) triangles_.push_back(leafTriangle(in_, leaf->prims[i]));
        stats.leaves++;
        stats.sahCost += relArea * leaf->count;
      } else {
        node.innerMask = uint8_t(node.innerMask | (1u << s));
        inner.push_back({s, static_cast<const BuildInner*>(c.node)});
        stats.sahCost += relArea;
      }
    }
    nodes_.resize(nodes_.size() + inner.size());
    nodes_[index] = node;
    for (size_t k = 0; k < inner.size(); ++k) {
      const BuildInner* child = inner[k].second;
      std::vector<Child> grandChildren;
      for (unsigned c = 0; c < child->childCount; ++c) grandChildren.push_back({child->children[c], child->bounds[c]});
      fill(node.childBase + uint32_t(k), grandChildren, depth + 1);
    }
  }

  // Slot bit a set: the child lies on the positive side of the node's centre along axis a. Greedy
  // by how far each child lies towards each slot's corner direction.
  static std::array<int, kWideBvhWidth> assignSlots(const std::vector<Child>& children) {
    Bounds3 box;
    for (const Child& c : children) {
      box.extend(c.bounds.lower);
      box.extend(c.bounds.upper);
    }
    const Vec3 centre = (box.lower + box.upper) * 0.5f;
    struct Candidate {
      float score;
      int child, slot;
    };
    std::vector<Candidate> candidates;
    for (size_t i = 0; i < children.size(); ++i) {
      const Vec3 d = (children[i].bounds.lower + children[i].bounds.upper) * 0.5f - centre;
      for (int s = 0; s < kWideBvhWidth; ++s) {
        float score = 0.0f;
        for (int a = 0; a < 3; ++a) score += ((s >> a) & 1) ? d[a] : -d[a];
        candidates.push_back({score, int(i), s});
      }
    }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const Candidate& x, const Candidate& y) { return x.score > y.score; });
    std::array<int, kWideBvhWidth> slotOf;
    slotOf.fill(-1);
    unsigned usedSlots = 0;
    for (const Candidate& c : candidates) {
      if (slotOf[size_t(c.child)] >= 0 || ((usedSlots >> c.slot) & 1u)) continue;
      slotOf[size_t(c.child)] = c.slot;
      usedSlots |= 1u << c.slot;
    }
    return slotOf;
  }

  // Slot s's box on the node's grid, rounded outwards in the traversal's own arithmetic.
  static void quantize(WideBvhNode& node, int s, const Bounds3& b) {
    for (int a = 0; a < 3; ++a) {
      const float origin = node.origin[a], step = wideBvhStep(node.exponent[a]);
      double lo = std::floor((double(b.lower[a]) - double(origin)) / double(step));
      double hi = std::ceil((double(b.upper[a]) - double(origin)) / double(step));
      uint32_t qlo = uint32_t(std::clamp(lo, 0.0, 255.0)), qhi = uint32_t(std::clamp(hi, 0.0, 255.0));
      while (qlo > 0 && wideBvhPlane(qlo, step, origin) > b.lower[a]) --qlo;
      while (qhi < 255 && wideBvhPlane(qhi, step, origin) < b.upper[a]) ++qhi;
      if (wideBvhPlane(qlo, step, origin) > b.lower[a] || wideBvhPlane(qhi, step, origin) < b.upper[a])
        throw Error("wide BVH: a child box does not fit its node's grid");
      node.lower[a][s] = uint8_t(qlo);
      node.upper[a][s] = uint8_t(qhi);
    }
  }

  const BuildInput& in_;
  std::vector<WideBvhNode>& nodes_;
  std::vector<BvhTriangle>& triangles_;
  BvhBuildStats& stats_;
  double rootArea_ = 1.0;
};

}  // namespace

Bvh Bvh::build(const Scene& scene) {
  SceneView v = scene.view();
  return build(scene.vertices(), std::vector<uint32_t>(v.indices, v.indices + 3 * size_t(v.triangleCount)));
}

Bvh Bvh::build(const std::vector<Vec3>& vertices, const std::vector<uint32_t>& indices) {
  auto start = std::chrono::steady_clock::now();
  BuildInput input{&vertices, &indices};
  Bvh bvh;
  bvh.stats_.inputTriangles = uint32_t(indices.size() / 3);
  buildWithEmbree(input, 2, kMaxLeafSize, kBvhMaxDepth, [&](const BuildNode* root, const Bounds3& rootBounds) {
    Flattener(input, bvh.nodes_, bvh.triangles_, bvh.stats_).flattenRoot(root, rootBounds);
  });
  bvh.stats_.nodes = uint32_t(bvh.nodes_.size());
  bvh.stats_.triangleReferences = uint32_t(bvh.triangles_.size());
  bvh.stats_.buildMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return bvh;
}

WideBvh WideBvh::build(const Scene& scene) {
  SceneView v = scene.view();
  return build(scene.vertices(), std::vector<uint32_t>(v.indices, v.indices + 3 * size_t(v.triangleCount)));
}

WideBvh WideBvh::build(const std::vector<Vec3>& vertices, const std::vector<uint32_t>& indices) {
  auto start = std::chrono::steady_clock::now();
  BuildInput input{&vertices, &indices};
  WideBvh bvh;
  bvh.stats_.inputTriangles = uint32_t(indices.size() / 3);
  buildWithEmbree(input, kWideBvhWidth, kWideBvhMaxLeafSize, kWideBvhMaxDepth,
                  [&](const BuildNode* root, const Bounds3& rootBounds) {
                    WideBvhFlattener(input, bvh.nodes_, bvh.triangles_, bvh.stats_).flattenRoot(root, rootBounds);
                  });
  bvh.stats_.nodes = uint32_t(bvh.nodes_.size());
  bvh.stats_.triangleReferences = uint32_t(bvh.triangles_.size());
  bvh.stats_.buildMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return bvh;
}

}  // namespace pvr
