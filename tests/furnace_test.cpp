// White furnace: a closed cube of uniform albedo rho and emission Le has radiance Le / (1 - rho)
// everywhere. The photon-map estimate (the paper's formulation) and the full shading (direct
// light by shadow rays + photon map for the rest) must both find it within a few percent.
#include <gtest/gtest.h>

#include <random>

#include "pvr/cpu/cpu_backend.h"
#include "test_scenes.h"

namespace pvr {
namespace {

// Mean radiance seen from the centre over random directions whose hit points lie at least
// `margin` from every edge of the cube (the density estimate near an edge also collects the
// adjacent wall's photons).
Vec3 meanRadiance(const CpuBackend& backend, const HashGridView& map, const GatherParams& params, float margin) {
  SceneView view = backend.scene().view();
  std::mt19937 rng(1);
  std::normal_distribution<float> normal;
  Vec3 sum{0, 0, 0};
  int used = 0;
  for (uint32_t i = 0; used < 4000; ++i) {
    Vec3 dir = normalize(Vec3(normal(rng), normal(rng), normal(rng)));
    Ray ray{{0, 0, 0}, dir};
    Hit hit;
    EXPECT_TRUE(backend.intersector().intersect(ray, INFINITY, hit)) << "the furnace must be closed";
    Vec3 p = view.surfacePoint(hit).position;
    int nearEdge = 0;
    for (int a = 0; a < 3; ++a) nearEdge += std::abs(p[a]) > 0.5f - margin;
    if (nearEdge > 1) continue;
    CounterRng counter(params.seed, i, 0);
    sum += radianceAlongRay(view, backend.intersector(), map, params, ray, counter);
    ++used;
  }
  return sum / float(used);
}

class Furnace : public ::testing::TestWithParam<float> {};

TEST_P(Furnace, PhotonMapAloneAndFullShadingMatchTheAnalyticRadiance) {
  const float rho = GetParam(), le = 1.0f, radius = 0.06f;
  Scene scene = test::furnaceBox(rho, le);
  CpuBackend backend(scene);
  const float expected = le / (1.0f - rho);
  for (ShadingMode mode : {ShadingMode::PhotonMapOnly, ShadingMode::Full}) {
    PhotonTraceParams tp;
    tp.photonCount = 512 * 512;
    tp.maxDepth = 64;  // rho^64 of the power is lost: negligible
    tp.storeDirect = mode == ShadingMode::PhotonMapOnly;
    HashGrid grid = HashGrid::build(backend.tracePhotons(tp), radius);
    GatherParams gp;
    gp.mode = mode;
    gp.density.radius = radius;
    Vec3 mean = meanRadiance(backend, grid.view(), gp, 2 * radius);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(mean[c], expected, 0.03f * expected) << "rho=" << rho << " mode=" << int(mode) << " channel " << c;
  }
}

INSTANTIATE_TEST_SUITE_P(Albedos, Furnace, ::testing::Values(0.3f, 0.5f, 0.8f));

}  // namespace
}  // namespace pvr
