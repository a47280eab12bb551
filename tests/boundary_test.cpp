// The density estimate where a lit plane meets a wall or ends (photon/boundary.h, --boundary
// clipped): the probes find the wall's distance and plane; on the floor next to the wall, and on a
// table top near its edge, the paper's sphere is off by the disc's missing area (and the wall's
// photons), and the clipped estimate is the surface's irradiance within its noise; far from walls
// and edges both are the same to the bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "pvr/cpu/cpu_backend.h"
#include "pvr/photon/gather.h"
#include "pvr/photon/hash_grid.h"
#include "pvr/scene/scene.h"

namespace pvr {
namespace {

// A white floor (y = 0, x > 0) meeting a white wall (x = 0, facing +x) under a sun travelling
// along (-1, -2, 0): the floor receives E cos = E 2 / sqrt 5, the wall E / sqrt 5, and the
// wall's photons travel downwards, towards the floor's side.
struct FloorAndWall {
  Scene scene;
  static constexpr float kIrradiance = 3.0f;
  FloorAndWall() {
    Material white;
    white.albedo = {1, 1, 1};
    const uint32_t id = scene.addMaterial(white, "white");
    scene.addMesh("floor", {{0, 0, -2}, {3, 0, -2}, {3, 0, 2}, {0, 0, 2}}, {}, {0, 2, 1, 0, 3, 2}, id);
    scene.addMesh("wall", {{0, 0, -2}, {0, 0, 2}, {0, 2, 2}, {0, 2, -2}}, {}, {0, 2, 1, 0, 3, 2}, id);
    PunctualLight sun;
    sun.kind = PunctualKind::Directional;
    sun.direction = normalize(Vec3(-1, -2, 0));
    sun.intensity = Vec3(kIrradiance);
    scene.addPunctualLight(sun, "sun");
    scene.finalize();
  }
  float floorIrradiance() const { return kIrradiance * 2.0f / std::sqrt(5.0f); }
};

// The share of a disc of radius r whose centre is d from a straight edge that lies on the near side.
double clippedDiscShare(double d, double r) {
  if (d >= r) return 1.0;
  const double cap = r * r * std::acos(d / r) - d * std::sqrt(r * r - d * d);
  return 1.0 - cap / (kPi * r * r);
}

// Every photon's first landing (no bounces), in a hash grid of cell r.
HashGrid directPhotons(const CpuBackend& backend, float r) {
  PhotonTraceParams tp;
  tp.photonCount = 1u << 22;
  tp.storeDirect = true;
  tp.maxDepth = 1;
  return HashGrid::build(backend.tracePhotons(tp), r);
}

// Photon-map-only radiance (red) at 32 points x = d along the line (d, y, -1.2 .. 1.2), each seen
// from above and beside it, averaged.
double meanRadiance(const CpuBackend& backend, const SceneView& view, const HashGrid& grid, float r, Boundary boundary,
                    float d, float y) {
  GatherParams params;
  params.mode = ShadingMode::PhotonMapOnly;
  params.density.radius = r;
  params.density.boundary = boundary;
  double sum = 0;
  const int n = 32;
  for (int k = 0; k < n; ++k) {
    const Vec3 p{d, y, -1.2f + 2.4f * (k + 0.5f) / n}, eye = p + Vec3(0.6f, 1.0f, 0.1f);
    CounterRng rng(1, uint32_t(k), 0);
    const GatherPoint gp = traceToGatherPoint(view, backend.intersector(), params, Ray{eye, normalize(p - eye)}, rng);
    sum += finishGather(grid.view(), gp, params.density).x;
  }
  return sum / n;
}

TEST(Boundary, ProbesFindTheWallsDistanceAndPlane) {
  FloorAndWall s;
  EmbreeIntersector intersector(s.scene);
  const SceneView view = s.scene.view();
  const float r = 0.2f;
  for (float d : {0.02f, 0.1f, 0.18f}) {
    double share = 0;  // the floor runs 3 further: no edge in reach
    const int n = 64;
    for (int k = 0; k < n; ++k) {
      const WallProbe probe = probeWalls(view, intersector, {d, 0, 0.3f}, {0, 1, 0}, r, (k + 0.5f) / n);
      share += probe.discShare / n;
      // The wall's plane: its normal (-x, into the wall) over its distance.
      EXPECT_NEAR(probe.wall.x, -1.0f / d, 1e-3f / d) << d;
      EXPECT_NEAR(probe.wall.y, 0.0f, 1e-5f);
      EXPECT_NEAR(probe.wall.z, 0.0f, 1e-5f);
    }
    // Over the rotation the sectors' mean is the clipped disc's area.
    EXPECT_NEAR(share, clippedDiscShare(d, r), 0.01) << "wall at " << d;
  }
  const WallProbe open = probeWalls(view, intersector, {1.0f, 0, 0.3f}, {0, 1, 0}, r, 0.3f);
  EXPECT_EQ(open.discShare, 1.0f);
  EXPECT_EQ(open.wall, Vec3(0.0f));
}

// Photon-map-only radiance on the floor, averaged over points along the wall: the sphere's is
// off (measured: 0.78 at 0.05 r from the wall, where the disc's missing part dominates, 1.04 at
// 0.75 r, where the wall's photons do), the clipped one is the floor's irradiance times albedo / pi
// within 3% (measured: 1.6%); past r from the wall both are the same bitwise.
TEST(Boundary, LitPlaneMeetingAWallKeepsItsIrradiance) {
  FloorAndWall s;
  CpuBackend backend(s.scene);
  const SceneView view = s.scene.view();
  const float r = 0.2f;
  const HashGrid grid = directPhotons(backend, r);
  const float expected = s.floorIrradiance() / kPi;
  for (float d : {0.01f, 0.05f, 0.1f, 0.15f}) {
    const double sphere = meanRadiance(backend, view, grid, r, Boundary::Sphere, d, 0.0f),
                 clipped = meanRadiance(backend, view, grid, r, Boundary::Clipped, d, 0.0f);
    std::printf("wall at %.2f r: sphere %.4f, clipped %.4f of the floor's radiance (clipped disc %.4f)\n", d / r,
                sphere / expected, clipped / expected, clippedDiscShare(d, r));
    EXPECT_NEAR(clipped, expected, 0.03 * expected) << "wall at " << d;
    if (d <= 0.05f) EXPECT_GT(std::fabs(sphere - expected), 0.05 * expected) << "the test sees the sphere's bias at " << d;
  }
  GatherParams sphere, walls;
  sphere.mode = walls.mode = ShadingMode::PhotonMapOnly;
  sphere.density.radius = walls.density.radius = r;
  walls.density.boundary = Boundary::Clipped;
  const Vec3 p{1.0f, 0.0f, 0.2f}, eye{1.5f, 1.0f, 0.4f};
  CounterRng a(3, 4, 5), b(3, 4, 5);
  const GatherPoint gs = traceToGatherPoint(view, backend.intersector(), sphere, Ray{eye, normalize(p - eye)}, a);
  const GatherPoint gw = traceToGatherPoint(view, backend.intersector(), walls, Ray{eye, normalize(p - eye)}, b);
  EXPECT_EQ(finishGather(grid.view(), gs, sphere.density), finishGather(grid.view(), gw, walls.density));
}

// A lit table top (y = 1) that ends at x = 0, the ground far below: the sphere's estimate near the
// edge is the clipped disc's share of the irradiance (no photon lands past the edge), the clipped
// estimate finds the edge by its rays down and keeps the irradiance within 5% (the bisection's
// steps of r / 8, averaged over the probes' rotation).
TEST(Boundary, LitTableTopKeepsItsIrradianceUpToTheEdge) {
  Scene scene;
  Material white;
  white.albedo = {1, 1, 1};
  const uint32_t id = scene.addMaterial(white, "white");
  scene.addMesh("top", {{0, 1, -2}, {3, 1, -2}, {3, 1, 2}, {0, 1, 2}}, {}, {0, 2, 1, 0, 3, 2}, id);
  scene.addMesh("ground", {{-3, 0, -3}, {3, 0, -3}, {3, 0, 3}, {-3, 0, 3}}, {}, {0, 2, 1, 0, 3, 2}, id);
  PunctualLight sun;
  sun.kind = PunctualKind::Directional;
  sun.direction = {0, -1, 0};
  sun.intensity = Vec3(2.0f);
  scene.addPunctualLight(sun, "sun");
  scene.finalize();
  CpuBackend backend(scene);
  const SceneView view = scene.view();
  const float r = 0.2f;
  const HashGrid grid = directPhotons(backend, r);
  const float expected = 2.0f / kPi;
  for (float d : {0.02f, 0.08f, 0.14f}) {
    const double sphere = meanRadiance(backend, view, grid, r, Boundary::Sphere, d, 1.0f),
                 clipped = meanRadiance(backend, view, grid, r, Boundary::Clipped, d, 1.0f);
    std::printf("edge at %.2f r: sphere %.4f (clipped disc %.4f), clipped %.4f of the top's radiance\n", d / r,
                sphere / expected, clippedDiscShare(d, r), clipped / expected);
    EXPECT_NEAR(sphere, expected * clippedDiscShare(d, r), 0.03 * expected) << "edge at " << d;
    EXPECT_NEAR(clipped, expected, 0.05 * expected) << "edge at " << d;
  }
}

}  // namespace
}  // namespace pvr
