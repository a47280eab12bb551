#pragma once
// Ray queries over a WideBvhView, written once for host and device: closest hit (`intersect`) and
// any hit (`occluded`), the Intersector interface of the shared photon-tracing and gathering code.
// The same watertight triangle test as the binary BVH (bvh_traversal.h), so both report the
// same hits.
//
// Traversal keeps one "node group" in registers: the hit inner children of the last node, as a
// bit mask ordered near to far for the ray's direction. It takes the nearest, pushes the rest as
// one stack entry (child base, remaining bits, inner mask) and tests the new node's 8 boxes at
// once; a node's leaf triangles are tested as soon as their boxes are hit, so that the closest
// hit's distance shrinks before deeper boxes are tested.
#include <cmath>
#include <cstring>

#include "pvr/accel/bvh_traversal.h"
#include "pvr/accel/wide_bvh.h"

#if defined(__CUDA_ARCH__)
#define PVR_WIDE_UNROLL _Pragma("unroll")
#define PVR_WIDE_NOINLINE __noinline__
#else
#define PVR_WIDE_UNROLL
#define PVR_WIDE_NOINLINE
#endif

namespace pvr {

// The grid step 2^e as a float, exactly, for the exponents the builder writes (-100..100).
PVR_HOST_DEVICE inline float wideBvhStep(int exponent) {
#ifdef __CUDA_ARCH__
  return __int_as_float((exponent + 127) << 23);
#else
  return std::ldexp(1.0f, exponent);
#endif
}

// A quantized plane in world space, as the traversal computes it (the builder checks its boxes
// against this very expression).
PVR_HOST_DEVICE inline float wideBvhPlane(uint32_t q, float step, float origin) { return fmaf(float(q), step, origin); }

struct WideBvhIntersector {
  WideBvhView bvh;
  // Alpha masking (any-hit): non-null, hits on texels its materials cut out are skipped (a pointer,
  // as BvhIntersector's).
  const SceneView* alphaScene = nullptr;
  // Where this thread keeps its traversal stack: word i at sharedStack[i * sharedStride], a column
  // of its block's shared memory (cuda::withSharedStack); null: an array in local memory, which
  // the GPU writes through to L2.
  int32_t* sharedStack = nullptr;
  uint32_t sharedStride = 0;

  // Stack entries one traversal can hold (one per wide level) and the 32-bit words they take.
  static constexpr int kStackSize = int(kWideBvhMaxDepth);
  static constexpr int kStackWords = 2 * kStackSize;

  PVR_HOST_DEVICE bool intersect(const Ray& ray, float tMax, Hit& hit) const {
    return traverse<false>(ray, tMax, hit);
  }
  PVR_HOST_DEVICE bool occluded(const Ray& ray, float tMax) const {
    Hit hit;
    return traverse<true>(ray, tMax, hit);
  }

 private:
  // The node's 80 bytes as 20 words; byte k is byte (k & 3) of word k >> 2.
  PVR_HOST_DEVICE static void loadNode(const WideBvhNode* node, uint32_t* w) {
#ifdef __CUDA_ARCH__
    const uint4* p = reinterpret_cast<const uint4*>(node);
    PVR_WIDE_UNROLL
    for (int i = 0; i < 5; ++i) {
      uint4 q = __ldg(p + i);
      w[4 * i] = q.x, w[4 * i + 1] = q.y, w[4 * i + 2] = q.z, w[4 * i + 3] = q.w;
    }
#else
    memcpy(w, node, sizeof(WideBvhNode));
#endif
  }

  PVR_HOST_DEVICE static uint32_t byteAt(const uint32_t* w, int k) { return (w[k >> 2] >> (8 * (k & 3))) & 0xffu; }

  PVR_HOST_DEVICE static int highestBit(uint32_t x) {
#ifdef __CUDA_ARCH__
    return 31 - __clz(x);
#else
    return 31 - __builtin_clz(x);
#endif
  }
  PVR_HOST_DEVICE static int lowestBit(uint32_t x) {
#ifdef __CUDA_ARCH__
    return __ffs(x) - 1;
#else
    return __builtin_ctz(x);
#endif
  }
  PVR_HOST_DEVICE static uint32_t bitCount(uint32_t x) {
#ifdef __CUDA_ARCH__
    return uint32_t(__popc(x));
#else
    return uint32_t(__builtin_popcount(x));
#endif
  }

  // Not inlined on the device: the 8-way unrolled node test is large, and a kernel that traces
  // from several call sites (camera ray, shadow rays, specular chains) would otherwise hold a copy
  // per site and thrash the instruction cache (Sponza's eye pass ran at half the speed it did
  // with the binary BVH, while the standalone ray kernels ran 2-3x faster).
  template <bool AnyHit>
  PVR_HOST_DEVICE PVR_WIDE_NOINLINE bool traverse(const Ray& ray, float tMax, Hit& hit) const {
    if (bvh.nodeCount == 0) return false;
    WatertightRay wr(ray);
    Vec3 invDir{1.0f / ray.dir.x, 1.0f / ray.dir.y, 1.0f / ray.dir.z};
    // Visiting order: key = slot ^ nearSide, highest key first. Along an axis the ray travels
    // up, the children on the lower side (slot bit 0) come first.
    const uint32_t nearSide = (ray.dir.x >= 0.0f ? 1u : 0u) | (ray.dir.y >= 0.0f ? 2u : 0u) | (ray.dir.z >= 0.0f ? 4u : 0u);
    int32_t localStack[kStackWords];  // untouched when the stack is in shared memory
    int sp = 0;
    auto push = [&](uint32_t base, uint32_t bits) {
      if (sharedStack) {
        sharedStack[uint32_t(2 * sp) * sharedStride] = int32_t(base);
        sharedStack[uint32_t(2 * sp + 1) * sharedStride] = int32_t(bits);
      } else {
        localStack[2 * sp] = int32_t(base);
        localStack[2 * sp + 1] = int32_t(bits);
      }
      ++sp;
    };
    auto pop = [&](uint32_t& base, uint32_t& bits) {
      --sp;
      if (sharedStack) {
        base = uint32_t(sharedStack[uint32_t(2 * sp) * sharedStride]);
        bits = uint32_t(sharedStack[uint32_t(2 * sp + 1) * sharedStride]);
      } else {
        base = uint32_t(localStack[2 * sp]);
        bits = uint32_t(localStack[2 * sp + 1]);
      }
    };
    // The group: inner children from groupBase; bits 0-7 the keys still to visit, bits 8-15 the
    // inner mask by slot. The root is the only child of a virtual node, in slot 0.
    uint32_t groupBase = 0, group = (1u << nearSide) | (1u << 8);
    bool found = false;
    Hit closest;  // in registers until the end: `hit` may live in the caller's local memory
    while (true) {
      if ((group & 0xffu) == 0) {
        if (sp == 0) break;
        pop(groupBase, group);
      }
      const int key = highestBit(group & 0xffu);
      group &= ~(1u << key);
      const int slot = key ^ int(nearSide);
      const uint32_t nodeIndex = groupBase + bitCount((group >> 8) & ((1u << slot) - 1u));
      if (group & 0xffu) push(groupBase, group);

      uint32_t w[20];
      loadNode(bvh.nodes + nodeIndex, w);
      const Vec3 origin{wordAsFloat(w[0]), wordAsFloat(w[1]), wordAsFloat(w[2])};
      const float step[3] = {wideBvhStep(int(int8_t(byteAt(w, 12)))), wideBvhStep(int(int8_t(byteAt(w, 13)))),
                             wideBvhStep(int(int8_t(byteAt(w, 14))))};
      const uint32_t innerMask = byteAt(w, 15);
      uint32_t innerKeys = 0, triangleBits = 0;
      PVR_WIDE_UNROLL
      for (int s = 0; s < kWideBvhWidth; ++s) {
        const uint32_t leaf = byteAt(w, 24 + s);
        const bool inner = (innerMask >> s) & 1u;
        if (!inner && leaf == 0) continue;  // an empty slot
        float t0[3], t1[3];
        PVR_WIDE_UNROLL
        for (int a = 0; a < 3; ++a) {
          const float o = a == 0 ? ray.origin.x : (a == 1 ? ray.origin.y : ray.origin.z);
          const float inv = a == 0 ? invDir.x : (a == 1 ? invDir.y : invDir.z);
          const float org = a == 0 ? origin.x : (a == 1 ? origin.y : origin.z);
          t0[a] = (wideBvhPlane(byteAt(w, 32 + 8 * a + s), step[a], org) - o) * inv;
          t1[a] = (wideBvhPlane(byteAt(w, 56 + 8 * a + s), step[a], org) - o) * inv;
        }
        const float tNear = fmaxf(fmaxf(fminf(t0[0], t1[0]), fminf(t0[1], t1[1])), fmaxf(fminf(t0[2], t1[2]), 0.0f));
        const float tFar = fminf(fminf(fmaxf(t0[0], t1[0]), fmaxf(t0[1], t1[1])), fminf(fmaxf(t0[2], t1[2]), tMax));
        // Robust slab test (Ize 2013): widen the far end by 2 ulps-ish so grazing rays keep their box.
        if (!(tNear <= tFar * 1.00000024f)) continue;
        if (inner) innerKeys |= 1u << (uint32_t(s) ^ nearSide);
        else triangleBits |= ((1u << (leaf >> 5)) - 1u) << (leaf & 31u);
      }
      const uint32_t triangleBase = w[5];
      while (triangleBits) {
        const int b = lowestBit(triangleBits);
        triangleBits &= triangleBits - 1u;
        if (!hitLeafTriangle(wr, bvh.triangles + triangleBase + uint32_t(b), alphaScene, tMax, closest)) continue;
        if (AnyHit) return true;
        found = true;
      }
      groupBase = w[4];
      group = innerKeys | (innerMask << 8);
    }
    if (found) hit = closest;
    return found;
  }

  PVR_HOST_DEVICE static float wordAsFloat(uint32_t u) {
#ifdef __CUDA_ARCH__
    return __uint_as_float(u);
#else
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
#endif
  }
};

}  // namespace pvr
