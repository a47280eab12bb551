// Energy bookkeeping of photon tracing: emitted photons carry exactly the lights' power, the
// result does not depend on thread scheduling, and photons never land on mirrors or glass.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <array>
#include <functional>

#include "pvr/cpu/cpu_backend.h"

namespace pvr {
namespace {

// Sum, in double, of the power of `count` emitted photons; `each` also sees every photon.
std::array<double, 3> emittedPower(const Scene& scene, uint32_t count,
                                   const std::function<void(const Photon&)>& each = {}) {
  PhotonTraceParams params;
  params.photonCount = count;
  SceneView view = scene.view();
  std::array<double, 3> sum = {0, 0, 0};
  for (uint32_t i = 0; i < count; ++i) {
    Photon p = emitPhoton(view, params, i);
    if (each) each(p);
    for (int c = 0; c < 3; ++c) sum[c] += p.power[c];
  }
  return sum;
}

TEST(PhotonEnergy, EmittedPhotonsCarryExactlyTheLightPower) {
  Scene scene = builtinScene("cornell");
  const uint32_t n = 100000;
  Vec3 total = scene.totalLightPower();
  auto sum = emittedPower(scene, n, [&](const Photon& p) {
    // One light colour: every photon carries exactly Phi / N.
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(p.power[c], total[c] / n, 1e-5 * total[c] / n);
    ASSERT_NEAR(length(p.direction), 1.0f, 1e-5f);
  });
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], total[c], 1e-4 * total[c]);
  // The Cornell light: Le = (17, 12, 4) over 130 x 105 mm, scaled by 1/556.
  float area = (130.0f / 556.0f) * (105.0f / 556.0f);
  EXPECT_NEAR(total.x, 17.0f * kPi * area, 1e-3f);
}

TEST(PhotonEnergy, LightsOfDifferentColoursSumToTheirPower) {
  // Two lights of different colour and size: the expected total is still exact, so the sum
  // over many photons converges to it.
  Scene scene = builtinScene("cornell");
  Material blue;
  blue.emission = {1, 2, 40};
  uint32_t id = scene.addMaterial(blue, "blue light");
  scene.addMesh("blue light", {{-0.4f, 0.9f, -0.4f}, {-0.2f, 0.9f, -0.4f}, {-0.2f, 0.9f, -0.2f}, {-0.4f, 0.9f, -0.2f}}, {},
                {0, 1, 2, 0, 2, 3}, id);
  scene.finalize();
  auto sum = emittedPower(scene, 400000);
  Vec3 total = scene.totalLightPower();
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], total[c], 0.01 * total[c]) << "channel " << c;
}

TEST(PhotonEnergy, TracingIsDeterministicAcrossThreadCounts) {
  Scene scene = builtinScene("cornell-caustics");
  CpuBackend backend(scene);
  PhotonTraceParams params;
  params.photonCount = 20000;
  std::vector<Photon> parallel = backend.tracePhotons(params);
  std::vector<Photon> serial;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    serial = backend.tracePhotons(params);
  }
  ASSERT_EQ(parallel.size(), serial.size());
  for (size_t i = 0; i < serial.size(); ++i) {
    ASSERT_EQ(parallel[i].position, serial[i].position);
    ASSERT_EQ(parallel[i].power, serial[i].power);
  }
  params.seed = 2;
  EXPECT_NE(backend.tracePhotons(params)[0].position, serial[0].position) << "the seed must matter";
}

TEST(PhotonEnergy, PhotonsAreStoredOnlyOnDiffuseSurfaces) {
  Scene scene = builtinScene("cornell-caustics");
  CpuBackend backend(scene);
  PhotonTraceParams params;
  params.photonCount = 128 * 128;
  params.storeDirect = true;
  std::vector<Photon> photons = backend.tracePhotons(params);
  ASSERT_GT(photons.size(), params.photonCount / 2);
  // The spheres (from builtin.cpp): radius 0.17, centres below. No photon may lie on them.
  const Vec3 centres[2] = {{-0.2f, 0.17f, -0.22f}, {0.2f, 0.19f, 0.1f}};
  for (const Photon& p : photons)
    for (const Vec3& c : centres) ASSERT_GT(std::abs(length(p.position - c) - 0.17f), 2e-3f);
}

TEST(PhotonEnergy, GlassSphereFocusesACausticOnTheFloor) {
  // Without direct photons the floor holds only indirect and caustic photons. Under the glass
  // sphere, offset away from the light, the caustic concentrates them far above the floor's
  // indirect density elsewhere.
  Scene scene = builtinScene("cornell-caustics");
  CpuBackend backend(scene);
  PhotonTraceParams params;
  params.photonCount = 256 * 256;
  std::vector<Photon> photons = backend.tracePhotons(params);
  auto powerInDisk = [&](float x, float z) {
    float sum = 0;
    for (const Photon& p : photons) {
      float dx = p.position.x - x, dz = p.position.z - z;
      if (p.position.y < 1e-3f && dx * dx + dz * dz < 0.06f * 0.06f) sum += luminance(p.power);
    }
    return sum;
  };
  float caustic = powerInDisk(0.25f, 0.12f), open = powerInDisk(0.0f, 0.38f);
  EXPECT_GT(open, 0.0f);
  EXPECT_GT(caustic, 3.0f * open) << "caustic " << caustic << " vs open floor " << open;
}

TEST(PhotonEnergy, NoDirectPhotonsUnlessAsked) {
  Scene scene = builtinScene("cornell");
  CpuBackend backend(scene);
  PhotonTraceParams params;
  params.photonCount = 4096;
  params.maxDepth = 1;  // a single interaction: every stored photon would be direct
  EXPECT_TRUE(backend.tracePhotons(params).empty());
  params.storeDirect = true;
  EXPECT_GT(backend.tracePhotons(params).size(), 3000u);  // most hit a diffuse wall before leaving the box
}

}  // namespace
}  // namespace pvr
