// The surface cache (view-independent density estimation, photon/surface_cache.h): each cell's
// estimate is the brute-force estimate at the centroid of its points; interpolation reproduces
// linear fields; walls of a corner never share cells; insertion order, a second eye's points and
// a full table change nothing they should not; and whole frames keep the per-pixel scheme's
// error against a converged reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>

#include "pvr/cpu/cpu_frame_backend.h"
#include "pvr/image/image_compare.h"
#include "pvr/photon/hash_grid.h"
#include "pvr/photon/host_surface_cache.h"
#include "pvr/reference/progressive_reference.h"
#include "pvr/render/renderer.h"

namespace pvr {
namespace {

// A Lambertian gather point on a surface of normal n.
GatherPoint lambertianPoint(Vec3 p, Vec3 n) {
  GatherPoint g;
  g.position = p;
  g.normal = n;
  g.weight = Vec3(1.0f / kPi);
  return g;
}

// A jittered grid of points on the floor y = 0 (normal +y) over [x0, x1] x [z0, z1].
std::vector<GatherPoint> floorPoints(float x0, float x1, float z0, float z1, int perSide, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<GatherPoint> points;
  for (int i = 0; i < perSide; ++i)
    for (int j = 0; j < perSide; ++j)
      points.push_back(lambertianPoint({x0 + (x1 - x0) * (i + u(rng)) / perSide, 0.0f, z0 + (z1 - z0) * (j + u(rng)) / perSide},
                                       {0, 1, 0}));
  return points;
}

std::vector<Photon> floorPhotons(size_t n, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Photon> photons;
  for (size_t i = 0; i < n; ++i) {
    const float x = u(rng), z = u(rng);
    // Brighter towards +x, some arriving from below (which the estimate must ignore).
    photons.push_back({{x, 0.0f, z}, Vec3(0.5f + 0.5f * x), {0.3f * u(rng), i % 7 == 0 ? 1.0f : -1.0f, 0.3f * u(rng)}});
  }
  return photons;
}

// 5,000 floor photons in a hash grid of radius 0.1, and the radius estimate over it.
struct FloorMap {
  HashGrid grid;
  DensityParams density;
};
FloorMap floorMap(std::mt19937& rng) {
  FloorMap m{HashGrid::build(floorPhotons(5000, rng), 0.1f), DensityParams()};
  m.density.radius = 0.1f;
  return m;
}

// Every cell of the table: key to estimate.
std::map<uint64_t, SurfaceCellEstimate> cellsOf(HostSurfaceCache& cache) {
  std::map<uint64_t, SurfaceCellEstimate> cells;
  const SurfaceCacheView v = cache.view();
  for (uint32_t s = 0; s < v.capacity; ++s)
    if (v.keys[s] != kNoSurfaceCell) cells[v.keys[s]] = v.estimates[s];
  return cells;
}

TEST(SurfaceCache, KeysRoundTripAndNormalsFallInTheirBuckets) {
  const int cells[][3] = {{0, 0, 0}, {-1, 7, 3}, {kCellCoordinateBias - 1, -kCellCoordinateBias, 12}};
  for (const auto& c : cells)
    for (uint32_t bucket = 0; bucket < 6; ++bucket) {
      const uint64_t key = surfaceCellKey(c, bucket);
      ASSERT_NE(key, kNoSurfaceCell);
      int back[3];
      cellOfSurfaceKey(key, back);
      EXPECT_EQ(back[0], c[0]);
      EXPECT_EQ(back[1], c[1]);
      EXPECT_EQ(back[2], c[2]);
      EXPECT_EQ(uint32_t(key >> (3 * kCellCoordinateBits)), bucket);
    }
  const int outside[3] = {kCellCoordinateBias, 0, 0};
  EXPECT_EQ(surfaceCellKey(outside, 0), kNoSurfaceCell);
  int far[3];
  surfaceCellOf({1e9f, 0, 0}, 10.0f, far);
  EXPECT_EQ(surfaceCellKey(far, 0), kNoSurfaceCell);
  surfaceCellOf({NAN, 0, 0}, 10.0f, far);
  EXPECT_EQ(surfaceCellKey(far, 0), kNoSurfaceCell);
  EXPECT_EQ(normalBucket({0, 1, 0}), 2u);
  EXPECT_EQ(normalBucket({0, -1, 0}), 3u);
  EXPECT_EQ(normalBucket({-0.9f, 0.1f, 0.4f}), 1u);
  EXPECT_EQ(normalBucket({0.1f, 0.2f, 0.97f}), 4u);
}

TEST(SurfaceCache, EachCellIsTheBruteForceEstimateAtItsPointsCentroid) {
  std::mt19937 rng(3);
  const float radius = 0.1f, cellSize = 0.025f;
  const std::vector<Photon> photons = floorPhotons(20000, rng);
  const HashGrid grid = HashGrid::build(photons, radius);
  const std::vector<GatherPoint> points = floorPoints(-0.5f, 0.5f, -0.5f, 0.5f, 200, rng);
  HostSurfaceCache cache;
  cache.reset(cellSize, surfaceCacheCapacity(points.size(), 0));
  cache.insert(points.data(), points.size());
  DensityParams density;
  density.radius = radius;
  cache.estimateCreated(grid.view(), density);
  // Brute force: the cells' centroids in double, then the photons within the radius.
  std::map<uint64_t, std::pair<Vec3, int>> centroid;
  for (const GatherPoint& p : points) {
    int c[3];
    surfaceCellOf(p.position, 1.0f / cellSize, c);
    auto& [sum, count] = centroid[surfaceCellKey(c, normalBucket(p.normal))];
    sum += p.position;
    ++count;
  }
  const auto cells = cellsOf(cache);
  ASSERT_EQ(cells.size(), centroid.size());
  EXPECT_EQ(cache.cells(), cells.size());
  EXPECT_EQ(cache.unplacedPoints(), 0u);
  for (const auto& [key, estimate] : cells) {
    ASSERT_TRUE(centroid.count(key));
    const auto& [sum, count] = centroid[key];
    const Vec3 expected = sum / float(count);
    EXPECT_LT(length(estimate.point - expected), 1e-5f * cellSize * 40) << "key " << key;
    Vec3 flux{0, 0, 0};
    for (const Photon& ph : photons)
      if (photonDistance2(estimate.point, ph.position) <= radius * radius && dot(ph.direction, Vec3(0, 1, 0)) < 0.0f)
        flux += ph.power;
    flux *= 1.0f / (kPi * radius * radius);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(estimate.flux[a], flux[a], 1e-4f * std::max(flux[a], 1.0f)) << "key " << key;
  }
}

// Fills every cell's estimate with f(cell centre) and reads the cache back between cells.
TEST(SurfaceCache, InterpolationReproducesConstantAndLinearFields) {
  std::mt19937 rng(5);
  const float cellSize = 0.05f;
  const std::vector<GatherPoint> points = floorPoints(-0.5f, 0.5f, -0.5f, 0.5f, 300, rng);
  HostSurfaceCache cache;
  cache.reset(cellSize, surfaceCacheCapacity(points.size(), 0));
  cache.insert(points.data(), points.size());
  const SurfaceCacheView v = cache.view();
  auto field = [](float x, float z) { return Vec3(2.0f + 3.0f * x - z, 1.0f, 0.5f + z); };
  for (uint32_t s = 0; s < v.capacity; ++s) {
    if (v.keys[s] == kNoSurfaceCell) continue;
    int c[3];
    cellOfSurfaceKey(v.keys[s], c);
    v.estimates[s].point = {(c[0] + 0.5f) * cellSize, 0.0f, (c[2] + 0.5f) * cellSize};
    v.estimates[s].flux = field(v.estimates[s].point.x, v.estimates[s].point.z);
  }
  std::uniform_real_distribution<float> u(-0.42f, 0.42f);  // a cell away from the borders
  for (int i = 0; i < 1000; ++i) {
    const Vec3 p{u(rng), 0.0f, u(rng)};
    Vec3 flux;
    ASSERT_TRUE(cachedFluxDensity(v, p, {0, 1, 0}, flux));
    const Vec3 expected = field(p.x, p.z);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(flux[a], expected[a], 2e-5f) << p.x << ", " << p.z;
  }
  // Near the border the missing neighbours drop out: a constant field stays exact.
  for (uint32_t s = 0; s < v.capacity; ++s)
    if (v.keys[s] != kNoSurfaceCell) v.estimates[s].flux = Vec3(0.7f);
  for (const Vec3 p : {Vec3{0.499f, 0.0f, 0.499f}, Vec3{-0.499f, 0.0f, 0.2f}, Vec3{0.0f, 0.0f, -0.499f}}) {
    Vec3 flux;
    ASSERT_TRUE(cachedFluxDensity(v, p, {0, 1, 0}, flux));
    EXPECT_NEAR(flux.x, 0.7f, 1e-6f);
  }
  // A point off every cell's plane, or facing another way, finds nothing.
  Vec3 flux;
  EXPECT_FALSE(cachedFluxDensity(v, {0.1f, 0.03f, 0.1f}, {0, 1, 0}, flux));
  EXPECT_FALSE(cachedFluxDensity(v, {0.1f, 0.0f, 0.1f}, {0, -1, 0}, flux));
  EXPECT_FALSE(cachedFluxDensity(v, {0.1f, 0.0f, 0.1f}, {1, 0, 0}, flux));
}

// A floor meets a wall at x = 0.5: the floor's lookups next to the corner never see the wall.
TEST(SurfaceCache, TheWallsOfACornerDoNotShareCells) {
  std::mt19937 rng(9);
  const float cellSize = 0.05f;
  std::vector<GatherPoint> points = floorPoints(-0.5f, 0.5f, -0.5f, 0.5f, 100, rng);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 10000; ++i) points.push_back(lambertianPoint({0.5f, u(rng), u(rng) - 0.5f}, {-1, 0, 0}));
  HostSurfaceCache cache;
  cache.reset(cellSize, surfaceCacheCapacity(points.size(), 0));
  cache.insert(points.data(), points.size());
  const SurfaceCacheView v = cache.view();
  for (uint32_t s = 0; s < v.capacity; ++s) {
    if (v.keys[s] == kNoSurfaceCell) continue;
    Vec3 n;
    surfaceCellPoint(v, s, v.estimates[s].point, n);
    v.estimates[s].flux = Vec3(n.y > 0.5f ? 1.0f : 100.0f);
  }
  for (float z : {-0.3f, 0.0f, 0.27f}) {
    Vec3 floorFlux, wallFlux;
    ASSERT_TRUE(cachedFluxDensity(v, {0.499f, 0.0f, z}, {0, 1, 0}, floorFlux));
    ASSERT_TRUE(cachedFluxDensity(v, {0.5f, 0.001f, z}, {-1, 0, 0}, wallFlux));
    EXPECT_EQ(floorFlux.x, 1.0f);
    EXPECT_EQ(wallFlux.x, 100.0f);
  }
}

TEST(SurfaceCache, InsertionOrderAndThreadsDoNotChangeACell) {
  std::mt19937 rng(11);
  const auto [grid, density] = floorMap(rng);
  std::vector<GatherPoint> points = floorPoints(-0.6f, 0.6f, -0.6f, 0.6f, 150, rng);
  auto build = [&](const std::vector<GatherPoint>& in) {
    HostSurfaceCache cache;
    cache.reset(0.02f, surfaceCacheCapacity(in.size(), 0));
    cache.insert(in.data(), in.size());
    cache.estimateCreated(grid.view(), density);
    return cellsOf(cache);
  };
  const auto first = build(points);
  std::shuffle(points.begin(), points.end(), rng);
  const auto shuffled = build(points);
  ASSERT_EQ(first.size(), shuffled.size());
  for (const auto& [key, e] : first) {
    ASSERT_TRUE(shuffled.count(key));
    const SurfaceCellEstimate& f = shuffled.at(key);
    EXPECT_EQ(e.point.x, f.point.x);
    EXPECT_EQ(e.point.y, f.point.y);
    EXPECT_EQ(e.point.z, f.point.z);
    EXPECT_EQ(e.flux.x, f.flux.x);
  }
}

// A second pass (the other eye, or the next sample) keeps the cells it finds and adds the rest.
TEST(SurfaceCache, ALaterPassKeepsEarlierCellsAndAddsNewOnes) {
  std::mt19937 rng(13);
  const auto [grid, density] = floorMap(rng);
  const std::vector<GatherPoint> left = floorPoints(-0.5f, 0.2f, -0.5f, 0.5f, 100, rng);
  const std::vector<GatherPoint> right = floorPoints(-0.2f, 0.5f, -0.5f, 0.5f, 100, rng);
  HostSurfaceCache cache;
  cache.reset(0.025f, surfaceCacheCapacity(left.size() + right.size(), 0));
  cache.insert(left.data(), left.size());
  cache.estimateCreated(grid.view(), density);
  const auto afterLeft = cellsOf(cache);
  cache.insert(right.data(), right.size());
  cache.estimateCreated(grid.view(), density);
  const auto afterBoth = cellsOf(cache);
  size_t kept = 0;
  for (const auto& [key, e] : afterLeft) {
    ASSERT_TRUE(afterBoth.count(key));
    EXPECT_EQ(afterBoth.at(key).point.x, e.point.x);
    EXPECT_EQ(afterBoth.at(key).flux.y, e.flux.y);
    ++kept;
  }
  EXPECT_EQ(kept, afterLeft.size());
  // The right points cover x in [-0.2, 0.5]: new cells for x > 0.2 only, about 3/7 of theirs.
  const double added = double(afterBoth.size() - afterLeft.size());
  EXPECT_GT(added, 0.3 * afterLeft.size());
  EXPECT_LT(added, 0.6 * afterLeft.size());
  EXPECT_EQ(cache.cells(), afterBoth.size());
}

// A table too small for the cells: the points without a slot are counted and estimated on their
// own (finishGatherCached falls back), never lost.
TEST(SurfaceCache, AFullTableFallsBackToThePointsOwnEstimate) {
  std::mt19937 rng(17);
  const auto [grid, density] = floorMap(rng);
  const std::vector<GatherPoint> points = floorPoints(-0.5f, 0.5f, -0.5f, 0.5f, 200, rng);
  HostSurfaceCache cache;
  cache.reset(0.01f, 1024);  // 10,000 cells of points
  cache.insert(points.data(), points.size());
  cache.estimateCreated(grid.view(), density);
  EXPECT_EQ(cache.cells(), 1024u);
  EXPECT_GT(cache.unplacedPoints(), points.size() / 2);
  const SurfaceCacheView v = cache.view();
  size_t own = 0;
  for (const GatherPoint& p : points) {
    const Vec3 c = finishGatherCached(v, grid.view(), p, density);
    Vec3 flux;
    if (!cachedFluxDensity(v, p.position, p.normal, flux)) {
      const Vec3 expected = finishGather(grid.view(), p, density);
      EXPECT_EQ(c.x, expected.x);
      ++own;
    }
  }
  EXPECT_GT(own, 0u);
}

// Microfacet points (view-dependent) and points that need no estimate bypass the cache exactly.
TEST(SurfaceCache, GlossyPointsAreEstimatedPerPixel) {
  std::mt19937 rng(19);
  const auto [grid, density] = floorMap(rng);
  std::vector<GatherPoint> points = floorPoints(-0.5f, 0.5f, -0.5f, 0.5f, 50, rng);
  HostSurfaceCache cache;
  cache.reset(0.025f, surfaceCacheCapacity(points.size(), 0));
  cache.insert(points.data(), points.size());
  cache.estimateCreated(grid.view(), density);
  GatherPoint glossy = points[100];
  glossy.lobes = kLobeDiffuse | kLobeReflection;
  glossy.wo = normalize(Vec3(0.3f, 1.0f, 0.1f));
  glossy.bsdf.normal = {0, 1, 0};
  glossy.bsdf.baseColor = Vec3(0.8f);
  glossy.bsdf.alpha = 0.5f;
  glossy.weight = Vec3(1.0f);
  const Vec3 a = finishGatherCached(cache.view(), grid.view(), glossy, density);
  const Vec3 b = finishGather(grid.view(), glossy, density);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  GatherPoint none = points[3];
  none.weight = Vec3(0.0f);
  none.radiance = Vec3(0.25f);
  EXPECT_EQ(finishGatherCached(cache.view(), grid.view(), none, density).x, 0.25f);
}

// Whole frames on the CPU: the cache's images against a converged reference of the same view,
// beside the per-pixel scheme's, for both shading modes; the right eye adds few cells of its own.
TEST(SurfaceCache, FramesKeepThePerPixelErrorAgainstTheReference) {
  const Scene scene = builtinScene("cornell");
  StereoRig rig = scene.rig;
  rig.width = 96, rig.height = 108;
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  RenderOptions o;
  o.photonsX = o.photonsY = 256;
  o.gather.density.radius = 0.05f;
  RenderOptions ro = o;
  ro.photonsX = ro.photonsY = 512;
  ro.gather.seed = 77;
  ProgressiveReference reference(renderer, rig, ro, ReferenceSettings{0.7f, false});
  for (int i = 0; i < 24; ++i) reference.addPass();
  for (ShadingMode mode : {ShadingMode::Full, ShadingMode::PhotonMapOnly}) {
    o.gather.mode = mode;
    o.density = DensityScheme::PerPixel;
    const FrameResult perPixel = renderer.render(rig, o);
    o.density = DensityScheme::SurfaceCache;
    const FrameResult cached = renderer.render(rig, o);
    const char* what = mode == ShadingMode::Full ? "full shading" : "photon-map only";
    EXPECT_EQ(cached.cacheUnplaced, 0u) << what;
    // Both eyes see most of the box: the right eye adds a minority of the cells.
    o.eyes[1] = false;
    const FrameResult leftOnly = renderer.render(rig, o);
    o.eyes[1] = true;
    EXPECT_LT(double(cached.cacheCells), 1.5 * double(leftOnly.cacheCells)) << what;
    for (int e = 0; e < 2; ++e) {
      const Image truth = reference.image(Eye(e));
      const ReferenceError pixel = compareToReference(perPixel.eyes[e].image, truth);
      const ReferenceError cache = compareToReference(cached.eyes[e].image, truth);
      EXPECT_LT(cache.relMse, 1.05 * pixel.relMse) << what << ", eye " << e;
      EXPECT_NEAR(cache.meanRatio, pixel.meanRatio, 0.01) << what << ", eye " << e;
      EXPECT_GT(compareToReference(cached.eyes[e].image, perPixel.eyes[e].image).relMse, 0.0) << "not the same image";
    }
  }
}

}  // namespace
}  // namespace pvr
