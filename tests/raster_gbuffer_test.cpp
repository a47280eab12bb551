// Ray-VR's G-buffer pre-pass (--primary raster) on whatever Vulkan device this machine has
// (lavapipe in CI): the rasterised first hits are the traced ones, pixel by pixel, with each eye's
// asymmetric projection; frames rendered from them equal traced frames up to rounding; alpha
// cut-outs fall back to rays. Skips without a Vulkan driver unless PVR_REQUIRE_VULKAN=1 (CI sets
// it, so it cannot pass by skipping).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>

#include "pvr/cpu/cpu_backend.h"
#include "pvr/cpu/embree_intersector.h"
#include "pvr/image/image_compare.h"
#include "pvr/raster/gbuffer_raster.h"
#include "pvr/render/renderer.h"
#include "pvr/scene/scene.h"
#include "pvr/util/error.h"
#include "test_scenes.h"
#include "vulkan_test_context.h"

namespace pvr {
namespace {

// The default rig (asymmetric per-eye fields of view), small, the head turned and tilted.
StereoRig smallTurnedRig(const Scene& scene, int width, int height) {
  StereoRig rig = scene.rig;
  rig.width = width, rig.height = height;
  rig.head.orientation = rig.head.orientation * Quat::fromAxisAngle({0, 1, 0}, 0.2f) * Quat::fromAxisAngle({1, 0, 0.3f}, -0.1f);
  return rig;
}

TEST(RasterGBuffer, ClipTransformPutsEachPixelsCentreRayOnThatPixel) {
  Scene scene = loadScene("cornell");
  StereoRig rig = smallTurnedRig(scene, 1440, 1600);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (Eye eye : {Eye::Left, Eye::Right}) {
    const EyeCamera cam = rig.eye(eye);
    ASSERT_NE(cam.fov.angleLeft, -cam.fov.angleRight);  // asymmetric: the test means something
    const float nearDepth = 1e-3f;
    float m[16];
    rasterWorldToClip(cam, nearDepth, m);
    for (int i = 0; i < 1000; ++i) {
      const float px = unit(rng) * cam.width, py = unit(rng) * cam.height, t = 0.1f + 5.0f * unit(rng);
      const Ray ray = cam.generateRay(px, py);
      const Vec3 p = ray.origin + ray.dir * t;
      float clip[4];
      for (int r = 0; r < 4; ++r) clip[r] = m[r] * p.x + m[4 + r] * p.y + m[8 + r] * p.z + m[12 + r];
      // Vulkan's viewport: framebuffer x = (ndc + 1) / 2 * width, rows from the top.
      EXPECT_NEAR((clip[0] / clip[3] + 1.0f) * 0.5f * cam.width, px, 2e-3f * cam.width / 1440.0f);
      EXPECT_NEAR((clip[1] / clip[3] + 1.0f) * 0.5f * cam.height, py, 2e-3f * cam.height / 1600.0f);
      const float viewDepth = 1.0f / cam.inverseDepthOf(p);
      EXPECT_NEAR(clip[2] / clip[3], nearDepth / viewDepth, 1e-5f * nearDepth / viewDepth);  // reversed Z
    }
  }
}

// Rasterised against traced first hits of both eyes' pixel centres.
struct Registration {
  size_t pixels = 0, sameTriangle = 0, samePoint = 0, bothSky = 0;
  double worstDistanceOnSameTriangle = 0.0;
};

Registration registerAgainstRays(const Scene& scene, const StereoRig& rig, VulkanContext& vk) {
  GBufferRaster raster(vk, scene, false);
  const EyeCamera eyes[2] = {rig.eye(Eye::Left), rig.eye(Eye::Right)};
  raster.render(eyes);
  raster.waitDone();
  EmbreeIntersector embree(scene);
  const SceneView view = scene.view();
  const Bounds3 b = scene.bounds();
  const float diagonal = length(b.upper - b.lower);
  Registration r;
  for (int e = 0; e < 2; ++e) {
    const PrimaryHitsView hits = raster.hostView(Eye(e));
    for (int y = 0; y < rig.height; ++y)
      for (int x = 0; x < rig.width; ++x) {
        const Ray ray = eyes[e].generateRay(x + 0.5f, y + 0.5f);
        Hit traced, rasterised;
        embree.intersect(ray, INFINITY, traced);
        EXPECT_TRUE(rasterisedFirstHit(view, hits, x, y, ray, rasterised));  // no alpha in these scenes
        ++r.pixels;
        if (!traced.valid() && !rasterised.valid()) {
          ++r.bothSky, ++r.sameTriangle, ++r.samePoint;
          continue;
        }
        if (!traced.valid() || !rasterised.valid()) continue;
        const float apart = length((ray.origin + ray.dir * traced.t) - (ray.origin + ray.dir * rasterised.t));
        if (apart <= 1e-4f * diagonal) ++r.samePoint;
        if (traced.primId == rasterised.primId) {
          ++r.sameTriangle;
          r.worstDistanceOnSameTriangle = std::max(r.worstDistanceOnSameTriangle, double(apart / diagonal));
          EXPECT_NEAR(traced.u, rasterised.u, 2e-3f);
          EXPECT_NEAR(traced.v, rasterised.v, 2e-3f);
        }
      }
  }
  return r;
}

// The pass the context chooses (lavapipe: a pass per eye), a turned head whose view clips walls.
TEST(RasterGBuffer, FirstHitsAreTheTracedOnesPixelByPixel) {
  auto vk = test::vulkanContextOrSkip();
  if (!vk) GTEST_SKIP() << "no Vulkan device on this machine";
  for (const char* name : {"cornell", "cornell-caustics", "cornell-dense"}) {
    SCOPED_TRACE(name);
    Scene scene = loadScene(name);
    const Registration r = registerAgainstRays(scene, smallTurnedRig(scene, 160, 180), *vk);
    const double pixels = double(r.pixels);
    std::printf("%s: %zu pixels, same triangle %.4f, same point %.4f, sky %zu, worst on the same triangle %.2e of the diagonal\n",
                name, r.pixels, r.sameTriangle / pixels, r.samePoint / pixels, r.bothSky, r.worstDistanceOnSameTriangle);
    EXPECT_GT(r.bothSky, 0u) << "the turned head sees past the box: the sky's pixels are checked too";
    EXPECT_GE(r.samePoint / pixels, 0.998) << r.samePoint << " of " << r.pixels;
    EXPECT_GE(r.sameTriangle / pixels, std::string(name) == "cornell-dense" ? 0.99 : 0.998);
    EXPECT_LT(r.worstDistanceOnSameTriangle, 1e-5);
  }
}

// The multiview pass (the GPU's) against a pass per eye (what lavapipe gets, see GBufferViews), on
// a view lavapipe's multiview draws right: the head looking into the box, no triangle clipped.
// The same triangles and barycentrics in every pixel of both eyes.
TEST(RasterGBuffer, MultiviewAndAPassPerEyeDrawTheSameBuffer) {
  auto vk = test::vulkanContextOrSkip();
  if (!vk) GTEST_SKIP() << "no Vulkan device on this machine";
  Scene scene = loadScene("cornell");
  StereoRig rig = scene.rig;
  rig.width = 120, rig.height = 132;
  const EyeCamera eyes[2] = {rig.eye(Eye::Left), rig.eye(Eye::Right)};
  GBufferRaster multiview(*vk, scene, false, GBufferViews::Multiview), perEye(*vk, scene, false, GBufferViews::PassPerView);
  EXPECT_TRUE(multiview.multiview());
  EXPECT_FALSE(perEye.multiview());
  multiview.render(eyes);
  perEye.render(eyes);
  multiview.waitDone();
  perEye.waitDone();
  for (Eye eye : {Eye::Left, Eye::Right}) {
    const PrimaryHitsView a = multiview.hostView(eye), b = perEye.hostView(eye);
    size_t same = 0, pixels = size_t(rig.width) * rig.height, hit = 0;
    for (size_t i = 0; i < pixels; ++i) {
      same += a.prim[i] == b.prim[i] && a.barycentrics[i].x == b.barycentrics[i].x && a.barycentrics[i].y == b.barycentrics[i].y;
      hit += a.prim[i] != ~0u;
    }
    EXPECT_EQ(same, pixels);
    EXPECT_GT(hit, pixels / 2);
  }
}

FrameResult renderOnCpu(const Scene& scene, PrimaryVisibility primary, uint32_t seed, int width, int height,
                        StereoMode stereo = StereoMode::Separate) {
  Renderer renderer(scene, BackendKind::Cpu);
  renderer.rig() = smallTurnedRig(scene, width, height);
  RenderOptions& o = renderer.options();
  o.photonsX = o.photonsY = 128;
  o.primary = primary;
  o.stereo = stereo;
  o.gather.seed = seed;
  o.gather.samplesPerPixel = 2;  // the second sample is traced as before
  return renderer.renderFrame(renderer.rig().head);
}

// The pre-pass changes a frame by rounding only: far less than the frame's own noise (another
// seed), with the same first triangle in nearly every pixel. Separate eyes and gather reuse.
TEST(RasterGBuffer, FramesFromRasterisedHitsEqualTracedFramesUpToRounding) {
  auto vk = test::vulkanContextOrSkip();
  if (!vk) GTEST_SKIP() << "no Vulkan device on this machine";
  vk.reset();
  Scene scene = loadScene("cornell-caustics");
  for (StereoMode stereo : {StereoMode::Separate, StereoMode::Gather}) {
    SCOPED_TRACE(stereoModeName(stereo));
    const FrameResult rays = renderOnCpu(scene, PrimaryVisibility::Rays, 1, 96, 108, stereo);
    const FrameResult raster = renderOnCpu(scene, PrimaryVisibility::Raster, 1, 96, 108, stereo);
    const FrameResult otherNoise = renderOnCpu(scene, PrimaryVisibility::Rays, 2, 96, 108, stereo);
    EXPECT_GT(raster.timings.primaryMs, 0.0);
    for (int e = 0; e < 2; ++e) {
      const auto& a = *rays.eyes[e].firstPrim;
      const auto& b = *raster.eyes[e].firstPrim;
      size_t same = 0;
      for (size_t i = 0; i < a.size(); ++i) same += a[i] == b[i];
      EXPECT_GE(double(same) / double(a.size()), 0.998);
      const double rounding = compareToReference(raster.eyes[e].image, rays.eyes[e].image).relMse;
      const double noise = compareToReference(otherNoise.eyes[e].image, rays.eyes[e].image).relMse;
      EXPECT_LT(rounding, 0.01 * noise) << "raster vs rays " << rounding << ", seed 1 vs 2 " << noise;
    }
  }
}

// A quad whose left half (x < 0) is cut out, over a floor, seen from above: through the cut-out
// texels the eye sees the floor, with the pre-pass as with rays (those pixels are traced).
TEST(RasterGBuffer, CutOutTexelsAreSeenThroughAsByRays) {
  auto vk = test::vulkanContextOrSkip();
  if (!vk) GTEST_SKIP() << "no Vulkan device on this machine";
  vk.reset();
  Scene scene = test::cutOutQuadOverFloor();
  scene.rig.head.position = {0, 2, 0};
  scene.rig.head.orientation = Quat::fromAxisAngle({1, 0, 0}, -0.5f * kPi);  // looking down
  auto render = [&](PrimaryVisibility primary) {
    Renderer renderer(scene, BackendKind::Cpu);
    renderer.rig().width = 64, renderer.rig().height = 72;
    renderer.options().photonsX = renderer.options().photonsY = 32;
    renderer.options().primary = primary;
    return renderer.renderFrame(renderer.rig().head);
  };
  const FrameResult rays = render(PrimaryVisibility::Rays), raster = render(PrimaryVisibility::Raster);
  const StereoRig& rig = scene.rig;
  for (int e = 0; e < 2; ++e) {
    StereoRig small = rig;
    small.width = 64, small.height = 72;
    const EyeCamera cam = small.eye(Eye(e));
    const auto& a = *rays.eyes[e].firstPrim;
    const auto& b = *raster.eyes[e].firstPrim;
    int throughCutOut = 0, onQuad = 0;
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x) {
        const size_t i = size_t(y) * cam.width + x;
        const Ray ray = cam.generateRay(x + 0.5f, y + 0.5f);
        const float t = (0.5f - ray.origin.y) / ray.dir.y;
        const Vec3 p = ray.origin + ray.dir * t;
        const bool insideQuad = std::fabs(p.x) < 0.48f && std::fabs(p.z) < 0.48f;
        if (insideQuad && p.x < -0.02f) {
          ++throughCutOut;
          EXPECT_GE(b[i], 2u) << "pixel " << x << "," << y << " sees the floor through the cut-out";
        }
        if (insideQuad && p.x > 0.02f) {
          ++onQuad;
          EXPECT_LT(b[i], 2u) << "pixel " << x << "," << y << " sees the quad's opaque half";
        }
        if (std::fabs(p.x) > 0.02f && std::fabs(std::fabs(p.x) - 0.5f) > 0.02f && std::fabs(std::fabs(p.z) - 0.5f) > 0.02f) {
          EXPECT_EQ(a[i], b[i]) << "pixel " << x << "," << y;
        }
      }
    EXPECT_GT(throughCutOut, 100);
    EXPECT_GT(onQuad, 100);
  }
}


// The GPU's first-hit pre-pass (PrimaryHitsView::traced) hands the eye pass the hits it would have
// traced itself: shading from them is bit for bit shading in place, for centred and jittered first
// samples, through mirrors and glass (cornell-caustics) and through cut-out texels.
TEST(PrimaryHits, PreTracedFirstHitsShadeExactlyAsTracingInPlace) {
  Scene cutOut = test::cutOutQuadOverFloor();
  cutOut.rig.head.position = {0, 2, 0};
  cutOut.rig.head.orientation = Quat::fromAxisAngle({1, 0, 0}, -0.5f * kPi);  // looking down
  for (const Scene& scene : {loadScene("cornell-caustics"), cutOut}) {
    SCOPED_TRACE(scene.name);
    CpuBackend backend(scene);
    StereoRig rig = scene.rig;
    rig.width = 56, rig.height = 48;
    PhotonTraceParams tp;
    tp.photonCount = 1u << 14;
    const float radius = 0.06f;
    const HashGrid grid = HashGrid::build(backend.tracePhotons(tp), radius);
    const EyeCamera camera = rig.eye(Eye::Right);
    const size_t pixels = size_t(camera.width) * camera.height;
    for (bool jitter : {false, true}) {
      GatherParams params;
      params.density.radius = radius;
      params.jitterFirstSample = jitter;
      params.samplesPerPixel = 2;
      std::vector<Hit> hits(pixels);
      size_t valid = 0;
      for (int y = 0; y < camera.height; ++y)
        for (int x = 0; x < camera.width; ++x) {
          const Hit h = pixelFirstHit(backend.intersector(), params, camera, Eye::Right, x, y);
          hits[size_t(y) * camera.width + x] = h;
          valid += h.valid();
        }
      EXPECT_GT(valid, pixels / 2);
      GatherParams fromHits = params;
      fromHits.primary.traced = hits.data();
      fromHits.primary.width = camera.width;
      std::vector<PixelSample> a(pixels), b(pixels);
      backend.renderEye(camera, Eye::Right, params, grid.view(), a.data());
      backend.renderEye(camera, Eye::Right, fromHits, grid.view(), b.data());
      size_t differing = 0, lit = 0;
      for (size_t i = 0; i < pixels; ++i) {
        const Vec3 &p = a[i].radiance, &q = b[i].radiance;
        differing += p.x != q.x || p.y != q.y || p.z != q.z || a[i].firstPrim != b[i].firstPrim ||
                     a[i].inverseDepth != b[i].inverseDepth;
        lit += p.x > 0.0f;
      }
      EXPECT_EQ(differing, 0u) << "jittered first sample: " << jitter;
      EXPECT_GT(lit, pixels / 2);
    }
  }
}

}  // namespace
}  // namespace pvr
