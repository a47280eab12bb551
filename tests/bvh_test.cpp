// The GPU's BVH and traversal, run on the CPU: built by Embree's rtcBuildBVH, flattened, and
// traversed by the shared host+device code; checked against Embree's own intersector.
#include <gtest/gtest.h>

#include "pvr/accel/bvh_traversal.h"
#include "pvr/cpu/embree_intersector.h"
#include "pvr/scene/scene.h"
#include "pvr/util/rng.h"
#include "pvr/util/sampling.h"

namespace pvr {
namespace {

struct Agreement {
  size_t rays = 0, hitsAgree = 0, occlusionAgree = 0;
};

// Random rays from inside the scene's bounds in uniform directions: closest hit and any hit.
Agreement compareWithEmbree(const Scene& scene, size_t rays) {
  Bvh bvh = Bvh::build(scene);
  BvhIntersector ours{bvh.view()};
  EmbreeIntersector embree(scene);
  Bounds3 b = scene.bounds();
  Agreement a;
  for (uint32_t i = 0; i < rays; ++i) {
    CounterRng rng(3, i, 0);
    float ux = rng.uniform(), uy = rng.uniform(), uz = rng.uniform();
    Vec3 o = b.lower + b.extent() * Vec3(ux, uy, uz);
    float z = 1.0f - 2.0f * rng.uniform(), phi = 2.0f * kPi * rng.uniform(), s = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    Ray ray{o, {s * cosf(phi), s * sinf(phi), z}};
    Hit h0, h1;
    bool hit0 = ours.intersect(ray, INFINITY, h0), hit1 = embree.intersect(ray, INFINITY, h1);
    ++a.rays;
    if (hit0 == hit1 && (!hit0 || h0.primId == h1.primId || std::fabs(h0.t - h1.t) <= 1e-5f * h1.t + 1e-6f)) {
      ++a.hitsAgree;
      if (hit0 && h0.primId == h1.primId) {
        EXPECT_NEAR(h0.t, h1.t, 1e-4f * h1.t + 1e-6f);  // float rounding of coordinates near 1
        EXPECT_NEAR(h0.u, h1.u, 1e-3f);
        EXPECT_NEAR(h0.v, h1.v, 1e-3f);
      }
    }
    float tMax = 0.5f * rng.uniform() * length(b.extent());
    if (ours.occluded(ray, tMax) == embree.occluded(ray, tMax)) ++a.occlusionAgree;
  }
  return a;
}

TEST(Bvh, AgreesWithEmbreeOnTheCornellScenes) {
  for (const char* name : {"cornell", "cornell-caustics"}) {
    Agreement a = compareWithEmbree(builtinScene(name), 20000);
    // Rays that graze an edge shared by two triangles may pick either: a handful at most.
    EXPECT_GE(double(a.hitsAgree) / double(a.rays), 0.9995) << name;
    EXPECT_GE(double(a.occlusionAgree) / double(a.rays), 0.9995) << name;
  }
}

TEST(Bvh, StructureIsConsistent) {
  Scene scene = builtinScene("cornell-caustics");
  Bvh bvh = Bvh::build(scene);
  const BvhBuildStats& s = bvh.stats();
  EXPECT_EQ(s.inputTriangles, scene.triangleCount());
  EXPECT_GE(s.triangleReferences, s.inputTriangles);  // spatial splits only add references
  EXPECT_LE(s.maxDepth, uint32_t(BvhIntersector::kStackSize));
  // Every triangle is referenced, and each child box contains its leaf's clipped part at least
  // partly: here, every leaf triangle's box overlaps its parent's child box.
  std::vector<int> seen(scene.triangleCount(), 0);
  for (const BvhNode& n : bvh.nodes())
    for (int c = 0; c < 2; ++c) {
      if (n.child[c] >= 0) {
        EXPECT_LT(uint32_t(n.child[c]), bvh.nodes().size());
        continue;
      }
      for (uint32_t i = 0; i < n.count[c]; ++i) {
        const BvhTriangle& t = bvh.triangles()[~n.child[c] + i];
        seen[t.primId] = 1;
        for (int a = 0; a < 3; ++a) {
          float lo = fminf(t.v0[a], fminf(t.v1[a], t.v2[a])), hi = fmaxf(t.v0[a], fmaxf(t.v1[a], t.v2[a]));
          EXPECT_LE(n.bounds[6 * c + a], hi + 1e-6f);
          EXPECT_GE(n.bounds[6 * c + 3 + a], lo - 1e-6f);
        }
      }
    }
  for (uint32_t p = 0; p < scene.triangleCount(); ++p) EXPECT_EQ(seen[p], 1) << "triangle " << p;
}

// Watertightness: rays aimed exactly at the shared vertices and edge midpoints of a closed,
// finely tessellated sphere, from its centre, must all hit it.
TEST(Bvh, WatertightAtSharedEdgesAndVertices) {
  std::vector<Vec3> v;
  std::vector<uint32_t> idx;
  const int seg = 48, rings = 24;
  for (int j = 0; j <= rings; ++j)
    for (int i = 0; i <= seg; ++i) {
      float th = kPi * j / rings, ph = 2 * kPi * (i % seg) / seg;
      v.push_back({sinf(th) * cosf(ph), cosf(th), sinf(th) * sinf(ph)});
    }
  for (int j = 0; j < rings; ++j)
    for (int i = 0; i < seg; ++i) {
      uint32_t a = j * (seg + 1) + i, b = a + 1, c = a + seg + 1, d = c + 1;
      idx.insert(idx.end(), {a, b, c, b, d, c});
    }
  Bvh bvh = Bvh::build(v, idx);
  BvhIntersector ours{bvh.view()};
  Vec3 centre{0.013f, -0.021f, 0.007f};  // off-centre: no symmetric luck
  size_t misses = 0, rays = 0;
  for (size_t t = 0; t < idx.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      Vec3 a = v[idx[t + k]], b = v[idx[t + (k + 1) % 3]];
      for (Vec3 target : {a, (a + b) * 0.5f}) {
        Hit h;
        ++rays;
        if (!ours.intersect({centre, normalize(target - centre)}, INFINITY, h)) ++misses;
      }
    }
  EXPECT_EQ(misses, 0u) << "of " << rays << " rays through shared edges and vertices";
}

}  // namespace
}  // namespace pvr
