#pragma once
// Ray queries over a BvhView, written once for host and device: closest hit (`intersect`) and
// any hit (`occluded`), the Intersector interface of the shared photon-tracing and gathering
// code. The triangle test is watertight (Woop, Benthin and Wald, JCGT 2013): rays through a
// shared edge or vertex never slip between the triangles that share it. Barycentrics and
// primitive ids follow Embree's convention, so both backends report the same hits.
#include "pvr/accel/bvh.h"
#include "pvr/geometry/ray.h"
#include "pvr/shading/scene_view.h"

namespace pvr {

// Per-ray constants of the watertight test: the ray's axes permuted so that z is the dominant
// direction, then sheared so that the ray is +z. Stored as a 3x3 transform (no run-time
// component indexing, which would put arrays in GPU local memory).
struct WatertightRay {
  Vec3 rowX, rowY, rowZ;  ///< rows of shear * permutation
  Vec3 origin;

  PVR_HOST_DEVICE explicit WatertightRay(const Ray& ray) : origin(ray.origin) {
    Vec3 a{fabsf(ray.dir.x), fabsf(ray.dir.y), fabsf(ray.dir.z)};
    int kz = (a.x >= a.y && a.x >= a.z) ? 0 : (a.y >= a.z ? 1 : 2);
    int kx = kz == 2 ? 0 : kz + 1;
    int ky = kx == 2 ? 0 : kx + 1;
    if (ray.dir[kz] < 0.0f) {  // keep the winding
      int t = kx;
      kx = ky;
      ky = t;
    }
    float dz = ray.dir[kz];
    float sx = ray.dir[kx] / dz, sy = ray.dir[ky] / dz, sz = 1.0f / dz;
    rowX = unit(kx) - unit(kz) * sx;
    rowY = unit(ky) - unit(kz) * sy;
    rowZ = unit(kz) * sz;
  }

  PVR_HOST_DEVICE static Vec3 unit(int k) { return {k == 0 ? 1.0f : 0.0f, k == 1 ? 1.0f : 0.0f, k == 2 ? 1.0f : 0.0f}; }

  // Vertex relative to the origin, in the ray's sheared space.
  PVR_HOST_DEVICE Vec3 transform(Vec3 v) const {
    Vec3 d = v - origin;
    return {dot(rowX, d), dot(rowY, d), dot(rowZ, d)};
  }
};

// Watertight ray-triangle test; on a hit with tMin < t < tMax, sets t, u, v and returns true.
PVR_HOST_DEVICE inline bool intersectTriangleWatertight(const WatertightRay& r, Vec3 v0, Vec3 v1, Vec3 v2, float tMin,
                                                        float tMax, float& t, float& u, float& v) {
  Vec3 a = r.transform(v0), b = r.transform(v1), c = r.transform(v2);
  float e0 = c.x * b.y - c.y * b.x;  // weight of v0
  float e1 = a.x * c.y - a.y * c.x;  // weight of v1
  float e2 = b.x * a.y - b.y * a.x;  // weight of v2
  if (e0 == 0.0f || e1 == 0.0f || e2 == 0.0f) {  // on an edge in float: decide in double
    e0 = float(double(c.x) * double(b.y) - double(c.y) * double(b.x));
    e1 = float(double(a.x) * double(c.y) - double(a.y) * double(c.x));
    e2 = float(double(b.x) * double(a.y) - double(b.y) * double(a.x));
  }
  if ((e0 < 0.0f || e1 < 0.0f || e2 < 0.0f) && (e0 > 0.0f || e1 > 0.0f || e2 > 0.0f)) return false;
  float det = e0 + e1 + e2;
  if (det == 0.0f) return false;
  float tScaled = e0 * a.z + e1 * b.z + e2 * c.z;
  float invDet = 1.0f / det;
  float tHit = tScaled * invDet;
  if (!(tHit > tMin && tHit < tMax)) return false;
  t = tHit;
  u = e1 * invDet;
  v = e2 * invDet;
  return true;
}

// A leaf triangle's vertices and scene index (three 16-byte loads through the read-only cache).
PVR_HOST_DEVICE inline void loadBvhTriangle(const BvhTriangle* tri, Vec3& v0, Vec3& v1, Vec3& v2, uint32_t& prim) {
#ifdef __CUDA_ARCH__
  const float4* p = reinterpret_cast<const float4*>(tri);
  float4 a = __ldg(p), b = __ldg(p + 1), c = __ldg(p + 2);
  v0 = {a.x, a.y, a.z}, v1 = {b.x, b.y, b.z}, v2 = {c.x, c.y, c.z};
  prim = __float_as_uint(a.w);
#else
  v0 = tri->v0, v1 = tri->v1, v2 = tri->v2, prim = tri->primId;
#endif
}

// Alpha masking (any-hit) of a candidate hit: false where the triangle's material cuts the texel
// out. The material check is inline; the texture lookup is out of line, so that the traversal
// loops do not carry a copy of the texture sampler in their registers and instruction cache.
struct AlphaMask {
  PVR_HOST_DEVICE static bool passes(const SceneView* scene, uint32_t prim, float u, float v) {
    return scene == nullptr || !scene->material(prim).alphaTested() || texelPasses(*scene, prim, u, v);
  }
  PVR_HOST_DEVICE PVR_NOINLINE static bool texelPasses(const SceneView& scene, uint32_t prim, float u, float v) {
    return scene.alphaPasses(prim, u, v);
  }
};

// One leaf triangle against the ray, for both BVH layouts: true for a hit before tMax that the
// alpha mask keeps, which then becomes `closest` and shortens tMax.
PVR_HOST_DEVICE inline bool hitLeafTriangle(const WatertightRay& wr, const BvhTriangle* tri, const SceneView* alphaScene,
                                            float& tMax, Hit& closest) {
  Vec3 v0, v1, v2;
  uint32_t prim;
  loadBvhTriangle(tri, v0, v1, v2, prim);
  float t, u, v;
  if (!intersectTriangleWatertight(wr, v0, v1, v2, 0.0f, tMax, t, u, v)) return false;
  if (!AlphaMask::passes(alphaScene, prim, u, v)) return false;
  tMax = t;
  closest.t = t, closest.u = u, closest.v = v, closest.primId = prim;
  return true;
}

struct BvhIntersector {
  BvhView bvh;
  // Alpha masking (any-hit): non-null, hits on texels its materials cut out are skipped. A pointer
  // (on the GPU, to a copy of the view in device memory) keeps the intersector a few registers.
  const SceneView* alphaScene = nullptr;
  // Where this thread keeps its traversal stack: entry i at sharedStack[i * sharedStride], a
  // column of its block's shared memory (cuda::withSharedStack); null: an array in local memory.
  // On the GPU local memory is written through to L2: a ray kernel with local stacks spent 82 %
  // of L2's bandwidth on its pushes (Sibenik, H200), shared memory keeps them on the SM.
  int32_t* sharedStack = nullptr;
  uint32_t sharedStride = 0;

  // Entries a traversal can hold: one per level of the deepest tree the builder makes.
  static constexpr int kStackSize = int(kBvhMaxDepth);

  PVR_HOST_DEVICE bool intersect(const Ray& ray, float tMax, Hit& hit) const {
    return traverse<false>(ray, tMax, hit);
  }
  PVR_HOST_DEVICE bool occluded(const Ray& ray, float tMax) const {
    Hit hit;
    return traverse<true>(ray, tMax, hit);
  }

 private:
  // A node's two children: boxes (min xyz, max xyz each), child indices (~first triangle for a
  // leaf) and leaf triangle counts. The boxes are read at constant indices only; children and
  // counts are scalars, because the loop picks them by a run-time child, and an array indexed so
  // would live in local memory on the GPU.
  struct Children {
    float b[12];
    int32_t child0, child1;
    uint32_t count0, count1;
  };

  PVR_HOST_DEVICE static Children loadNode(const BvhNode* node) {
    Children c;
#ifdef __CUDA_ARCH__
    const float4* p = reinterpret_cast<const float4*>(node);
    float4 q0 = __ldg(p), q1 = __ldg(p + 1), q2 = __ldg(p + 2);
    int4 q3 = __ldg(reinterpret_cast<const int4*>(p + 3));
    c.b[0] = q0.x, c.b[1] = q0.y, c.b[2] = q0.z, c.b[3] = q0.w, c.b[4] = q1.x, c.b[5] = q1.y;
    c.b[6] = q1.z, c.b[7] = q1.w, c.b[8] = q2.x, c.b[9] = q2.y, c.b[10] = q2.z, c.b[11] = q2.w;
    c.child0 = q3.x, c.child1 = q3.y, c.count0 = uint32_t(q3.z), c.count1 = uint32_t(q3.w);
#else
    for (int i = 0; i < 12; ++i) c.b[i] = node->bounds[i];
    c.child0 = node->child[0], c.child1 = node->child[1], c.count0 = node->count[0], c.count1 = node->count[1];
#endif
    return c;
  }

  // Slab test of one child box: entry distance in tEnter, false if the ray misses it in (0, tMax).
  PVR_HOST_DEVICE static bool hitBox(const float* b, Vec3 org, Vec3 invDir, float tMax, float& tEnter) {
    float tx0 = (b[0] - org.x) * invDir.x, tx1 = (b[3] - org.x) * invDir.x;
    float ty0 = (b[1] - org.y) * invDir.y, ty1 = (b[4] - org.y) * invDir.y;
    float tz0 = (b[2] - org.z) * invDir.z, tz1 = (b[5] - org.z) * invDir.z;
    float tNear = fmaxf(fmaxf(fminf(tx0, tx1), fminf(ty0, ty1)), fmaxf(fminf(tz0, tz1), 0.0f));
    float tFar = fminf(fminf(fmaxf(tx0, tx1), fmaxf(ty0, ty1)), fminf(fmaxf(tz0, tz1), tMax));
    // Robust slab test (Ize 2013): widen the far end by 2 ulps-ish so grazing rays keep their box.
    tEnter = tNear;
    return tNear <= tFar * 1.00000024f;
  }

  template <bool AnyHit>
  PVR_HOST_DEVICE bool traverse(const Ray& ray, float tMax, Hit& hit) const {
    if (bvh.nodeCount == 0) return false;
    WatertightRay wr(ray);
    Vec3 invDir{1.0f / ray.dir.x, 1.0f / ray.dir.y, 1.0f / ray.dir.z};
    int32_t localStack[kStackSize];  // untouched when the stack is in shared memory
    int sp = 0;
    int32_t node = 0;
    bool found = false;
    Hit closest;  // in registers until the end: `hit` may live in the caller's local memory
    while (true) {
      const Children n = loadNode(bvh.nodes + node);
      float tEnter0, tEnter1;
      bool enter0 = hitBox(n.b, ray.origin, invDir, tMax, tEnter0);
      bool enter1 = hitBox(n.b + 6, ray.origin, invDir, tMax, tEnter1);
      // Leaf children: their triangles now, in child order, through one copy of the loop.
#ifdef __CUDA_ARCH__
#pragma unroll 1
#endif
      for (int c = 0; c < 2; ++c) {
        const int32_t child = c == 0 ? n.child0 : n.child1;
        if (!(c == 0 ? enter0 : enter1) || child >= 0) continue;
        const BvhTriangle* tri = bvh.triangles + ~child;
        const uint32_t count = c == 0 ? n.count0 : n.count1;
        for (uint32_t i = 0; i < count; ++i) {
          if (!hitLeafTriangle(wr, tri + i, alphaScene, tMax, closest)) continue;
          if (AnyHit) return true;
          found = true;
        }
      }
      enter0 = enter0 && n.child0 >= 0;
      enter1 = enter1 && n.child1 >= 0;
      if (enter0 && enter1) {
        const bool swap = tEnter1 < tEnter0;
        const int32_t farChild = swap ? n.child0 : n.child1;
        if (sharedStack) sharedStack[uint32_t(sp) * sharedStride] = farChild;
        else localStack[sp] = farChild;
        ++sp;
        node = swap ? n.child1 : n.child0;
      } else if (enter0) {
        node = n.child0;
      } else if (enter1) {
        node = n.child1;
      } else {
        if (sp == 0) break;
        --sp;
        node = sharedStack ? sharedStack[uint32_t(sp) * sharedStride] : localStack[sp];
      }
    }
    if (found) hit = closest;
    return found;
  }
};

}  // namespace pvr
