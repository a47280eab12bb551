// The GPU's BVHs and traversals, run on the CPU: built by Embree's rtcBuildBVH, flattened (binary,
// and 8-wide with quantized boxes), and traversed by the shared host+device code; checked against
// Embree's own intersector and against each other.
#include <gtest/gtest.h>

#include "pvr/accel/bvh_traversal.h"
#include "pvr/accel/wide_bvh_traversal.h"
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
template <class Accel, class Intersector>
Agreement compareWithEmbree(const Scene& scene, size_t rays) {
  Accel bvh = Accel::build(scene);
  Intersector ours{bvh.view()};
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
    Agreement a = compareWithEmbree<Bvh, BvhIntersector>(builtinScene(name), 20000);
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
template <class Accel, class Intersector>
void expectWatertightSphere() {
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
  Accel bvh = Accel::build(v, idx);
  Intersector ours{bvh.view()};
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

// Triangles nested towards a corner, each 0.85 times the last: input that asks for a deep tree
// (Embree's build makes it 22 levels deep; a chain would be 150). The build keeps within the
// traversal stack, which has no bound check, and a ray just under each triangle finds it.
TEST(Bvh, ANestOfShrinkingTrianglesStaysWithinTheTraversalStack) {
  // 150: the smallest is 3e-11 across, and the triangle test's products (cubes of the size) stay
  // normal floats.
  constexpr uint32_t kTriangles = 150;
  std::vector<Vec3> v;
  std::vector<uint32_t> idx;
  std::vector<float> size;
  float s = 1.0f;
  for (uint32_t k = 0; k < kTriangles; ++k, s *= 0.85f) {
    for (Vec3 p : {Vec3{s, 0.0f, s}, Vec3{0.0f, s, s}, Vec3{s, s, s}}) {
      idx.push_back(uint32_t(v.size()));
      v.push_back(p);
    }
    size.push_back(s);
  }
  Bvh bvh = Bvh::build(v, idx);
  EXPECT_GT(bvh.stats().maxDepth, 16u);  // a deep tree: the case the bound is for
  EXPECT_LE(bvh.stats().maxDepth, uint32_t(BvhIntersector::kStackSize));
  BvhIntersector ours{bvh.view()};
  for (uint32_t k = 0; k < kTriangles; ++k) {
    // Inside triangle k, above every smaller one (they lie at 0.85 s and below).
    Ray ray{{0.9f * size[k], 0.9f * size[k], 0.99f * size[k]}, {0.0f, 0.0f, 1.0f}};
    Hit h;
    ASSERT_TRUE(ours.intersect(ray, INFINITY, h)) << "triangle " << k;
    EXPECT_EQ(h.primId, k);
    EXPECT_TRUE(ours.occluded(ray, 0.02f * size[k])) << "triangle " << k;
    EXPECT_FALSE(ours.occluded(ray, 0.005f * size[k])) << "triangle " << k;
  }
}

TEST(Bvh, WatertightAtSharedEdgesAndVertices) { expectWatertightSphere<Bvh, BvhIntersector>(); }

// The wide BVH: the same hits as Embree and as the binary BVH, the same watertightness, and boxes
// that hold what they bound after quantization.
TEST(WideBvh, AgreesWithEmbreeOnTheCornellScenes) {
  for (const char* name : {"cornell", "cornell-caustics", "cornell-dense"}) {
    Agreement a = compareWithEmbree<WideBvh, WideBvhIntersector>(builtinScene(name), 20000);
    EXPECT_GE(double(a.hitsAgree) / double(a.rays), 0.9995) << name;
    EXPECT_GE(double(a.occlusionAgree) / double(a.rays), 0.9995) << name;
  }
}

TEST(WideBvh, WatertightAtSharedEdgesAndVertices) { expectWatertightSphere<WideBvh, WideBvhIntersector>(); }

// A soup of random triangles at scales from 1e-3 to 1e3 around an offset origin, so that the
// quantization grids' exponents span a wide range: every ray's closest hit and any hit equal the
// brute-force loop over all triangles with the same triangle test, to the bit.
TEST(WideBvh, HitsEqualBruteForceOverATriangleSoup) {
  std::vector<Vec3> v;
  std::vector<uint32_t> idx;
  for (uint32_t i = 0; i < 3000; ++i) {
    CounterRng rng(17, i, 0);
    float scale = powf(10.0f, -3.0f + 6.0f * rng.uniform());
    Vec3 c{1000.0f + 40.0f * rng.uniform(), -20.0f + 40.0f * rng.uniform(), 5.0f + 40.0f * rng.uniform()};
    // Every 7th triangle lies in an axis plane (zero-thickness boxes, as the Cornell box's walls).
    int flatAxis = i % 7 == 0 ? int(i / 7 % 3) : -1;
    for (int k = 0; k < 3; ++k) {
      Vec3 p{rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f};
      if (flatAxis >= 0) p[flatAxis] = 0.0f;
      idx.push_back(uint32_t(v.size()));
      v.push_back(c + p * scale);
    }
  }
  WideBvh bvh = WideBvh::build(v, idx);
  WideBvhIntersector ours{bvh.view()};
  size_t rays = 0, hits = 0;
  for (uint32_t i = 0; i < 20000; ++i) {
    CounterRng rng(19, i, 0);
    Vec3 o{1000.0f + 40.0f * rng.uniform(), -20.0f + 40.0f * rng.uniform(), 5.0f + 40.0f * rng.uniform()};
    Vec3 d;
    if (i % 4 == 0) {  // along an axis: direction components exactly 0
      d = Vec3(0.0f);
      d[int(i / 4 % 3)] = rng.uniform() < 0.5f ? -1.0f : 1.0f;
    } else {
      float z = 1.0f - 2.0f * rng.uniform(), phi = 2.0f * kPi * rng.uniform(), s = sqrtf(fmaxf(0.0f, 1.0f - z * z));
      d = {s * cosf(phi), s * sinf(phi), z};
    }
    Ray ray{o, d};
    WatertightRay wr(ray);
    float tBest = INFINITY;
    uint32_t bestPrim = ~0u;
    for (uint32_t t = 0; t < idx.size() / 3; ++t) {
      float th, u, vv;
      if (intersectTriangleWatertight(wr, v[idx[3 * t]], v[idx[3 * t + 1]], v[idx[3 * t + 2]], 0.0f, tBest, th, u, vv)) {
        tBest = th;
        bestPrim = t;
      }
    }
    Hit h;
    bool hit = ours.intersect(ray, INFINITY, h);
    ++rays;
    ASSERT_EQ(hit, bestPrim != ~0u) << "ray " << i;
    if (hit) {
      ++hits;
      EXPECT_EQ(h.t, tBest) << "ray " << i;  // equal t from two triangles may name either
    }
    float tMax = hit ? (i % 2 ? h.t * 1.001f : h.t * 0.999f) : 50.0f;
    EXPECT_EQ(ours.occluded(ray, tMax), hit && i % 2 == 1) << "ray " << i;
  }
  EXPECT_GT(hits, rays / 20);  // the soup is hit often enough to mean something
}

TEST(WideBvh, StructureIsConsistent) {
  Scene scene = builtinScene("cornell-caustics");
  WideBvh bvh = WideBvh::build(scene);
  const BvhBuildStats& s = bvh.stats();
  EXPECT_EQ(s.inputTriangles, scene.triangleCount());
  EXPECT_GE(s.triangleReferences, s.inputTriangles);
  EXPECT_LE(s.maxDepth, uint32_t(WideBvhIntersector::kStackSize) + 1);
  std::vector<int> seen(scene.triangleCount(), 0);
  std::vector<int> parents(bvh.nodes().size(), 0);
  parents[0] = 1;
  for (const WideBvhNode& n : bvh.nodes()) {
    uint32_t innerIndex = 0, leafTriangles = 0;
    for (int slot = 0; slot < kWideBvhWidth; ++slot) {
      float lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        float step = wideBvhStep(n.exponent[a]);
        lo[a] = wideBvhPlane(n.lower[a][slot], step, n.origin[a]);
        hi[a] = wideBvhPlane(n.upper[a][slot], step, n.origin[a]);
      }
      if ((n.innerMask >> slot) & 1) {
        EXPECT_EQ(n.leaf[slot], 0);
        uint32_t child = n.childBase + innerIndex++;
        ASSERT_LT(child, bvh.nodes().size());
        parents[child]++;
        continue;
      }
      uint32_t count = n.leaf[slot] >> 5, offset = n.leaf[slot] & 31;
      EXPECT_LE(count, kWideBvhMaxLeafSize);
      if (count) {
        EXPECT_EQ(offset, leafTriangles) << "leaves' triangles follow one another in slot order";
      }
      leafTriangles += count;
      for (uint32_t i = 0; i < count; ++i) {
        const BvhTriangle& t = bvh.triangles()[n.triangleBase + offset + i];
        seen[t.primId] = 1;
        for (int a = 0; a < 3; ++a) {  // the (possibly clipped) triangle overlaps its leaf's box
          EXPECT_LE(lo[a], fmaxf(t.v0[a], fmaxf(t.v1[a], t.v2[a])));
          EXPECT_GE(hi[a], fminf(t.v0[a], fminf(t.v1[a], t.v2[a])));
        }
      }
    }
  }
  for (size_t i = 0; i < parents.size(); ++i) EXPECT_EQ(parents[i], 1) << "node " << i << " has one parent";
  for (uint32_t p = 0; p < scene.triangleCount(); ++p) EXPECT_EQ(seen[p], 1) << "triangle " << p;
}

TEST(WideBvh, NoTrianglesMeansNoHit) {
  WideBvh bvh = WideBvh::build({}, {});
  EXPECT_EQ(bvh.nodes().size(), 0u);
  WideBvhIntersector ours{bvh.view()};
  Hit h;
  EXPECT_FALSE(ours.intersect({{0, 0, 0}, {0, 0, 1}}, INFINITY, h));
  EXPECT_FALSE(ours.occluded({{0, 0, 0}, {0, 0, 1}}, INFINITY));
  // One triangle: a root whose only slot is a leaf.
  WideBvh one = WideBvh::build({{-1, -1, 2}, {1, -1, 2}, {0, 1, 2}}, {0, 1, 2});
  WideBvhIntersector single{one.view()};
  ASSERT_TRUE(single.intersect({{0, 0, 0}, {0, 0, 1}}, INFINITY, h));
  EXPECT_FLOAT_EQ(h.t, 2.0f);
  EXPECT_EQ(h.primId, 0u);
}

}  // namespace
}  // namespace pvr
