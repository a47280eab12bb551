// Temporal anti-aliasing: reprojection round trips, convergence to the static image under a
// static camera (full resolution and foveated, from a history of another gaze), disocclusion
// detection checked against Embree visibility, clamping against ghosts, and history resets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "pvr/cpu/cpu_frame_backend.h"
#include "pvr/foveation/mask.h"
#include "pvr/render/renderer.h"
#include "pvr/temporal/taa_history.h"
#include "pvr/util/error.h"

namespace pvr {
namespace {

float maxDifference(const Image& a, const Image& b) {
  float worst = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) worst = std::max(worst, maxComponent(abs(a.pixels[i] - b.pixels[i])));
  return worst;
}

StereoRig smallRig(const Scene& scene, int width = 80, int height = 88) {
  StereoRig rig = scene.rig;
  rig.width = width, rig.height = height;
  return rig;
}

RenderOptions smallOptions() {
  RenderOptions o;
  o.photonsX = o.photonsY = 64;
  o.gather.density.radius = 0.08f;
  return o;
}

TEST(Temporal, ReprojectionRoundTrips) {
  Scene scene = builtinScene("cornell");
  StereoRig rig = smallRig(scene);
  EyeCamera camera = rig.eye(Eye::Left);
  for (int y = 0; y < rig.height; y += 7)
    for (int x = 0; x < rig.width; x += 5)
      for (float z : {0.3f, 1.7f, 40.0f}) {
        Vec3 world = camera.pointAt(x + 0.5f, y + 0.5f, 1.0f / z);
        EXPECT_NEAR(camera.inverseDepthOf(world), 1.0f / z, 1e-5f / z);
        float px, py;
        ASSERT_TRUE(camera.project(world, px, py));
        EXPECT_NEAR(px, x + 0.5f, 2e-3f);
        EXPECT_NEAR(py, y + 0.5f, 2e-3f);
        ASSERT_TRUE(camera.projectDirection(world - camera.pose.position, px, py));
        EXPECT_NEAR(px, x + 0.5f, 2e-3f);
        EXPECT_NEAR(py, y + 0.5f, 2e-3f);
      }
  // Catmull-Rom returns the pixel at its centre, and reproduces a linear ramp between centres.
  Image ramp(8, 6);
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 8; ++x) ramp.pixels[size_t(y) * 8 + x] = Vec3(float(x), float(y), 1.0f);
  Vec3 c = sampleCatmullRom(ramp.pixels.data(), 8, 6, 3.5f, 2.5f);
  EXPECT_EQ(c.x, 3.0f);
  EXPECT_EQ(c.y, 2.0f);
  c = sampleCatmullRom(ramp.pixels.data(), 8, 6, 4.25f, 2.9f);
  EXPECT_NEAR(c.x, 3.75f, 1e-5f);
  EXPECT_NEAR(c.y, 2.4f, 1e-5f);
  EXPECT_NEAR(c.z, 1.0f, 1e-6f);
}

// With a static camera and an unchanging image the output approaches that image geometrically:
// the clamp never moves history away from it, and each frame keeps (1 - blend) of the error.
void expectConvergence(FrameRenderer& renderer, const StereoRig& rig, RenderOptions first, RenderOptions still) {
  renderer.resetHistory();
  renderer.setFreshNoisePerFrame(false);  // every frame the same numbers: TAA's own convergence
  still.temporal.enabled = first.temporal.enabled = false;
  FrameResult target = renderer.render(rig, still);
  still.temporal.enabled = first.temporal.enabled = true;
  FrameResult start = renderer.render(rig, first);  // the history: another frame
  EXPECT_EQ(start.historyPixels[0], 0u) << "the first frame has no history";
  float error0 = maxDifference(start.eyes[0].image, target.eyes[0].image);
  ASSERT_GT(error0, 0.05f) << "the starting history should differ";
  const float keep = 1.0f - still.temporal.taa.blend;
  float bound = error0;
  const size_t pixels = size_t(rig.width) * rig.height;
  for (int frame = 1; frame <= 60; ++frame) {
    FrameResult r = renderer.render(rig, still);
    bound *= keep;
    for (int e = 0; e < 2; ++e) {
      float error = maxDifference(r.eyes[e].image, target.eyes[e].image);
      ASSERT_LE(error, 1.02f * bound + 1e-5f) << "eye " << e << ", frame " << frame;
      // A static head keeps its history: all of it once the frames agree. Right after the gaze
      // jumped, the new fovea's exact depths do not match the old blends at silhouettes: those
      // pixels restart, sharp at once.
      if (frame == 1) EXPECT_GE(double(r.historyPixels[e]), 0.75 * double(pixels)) << "eye " << e;
      else EXPECT_EQ(r.historyPixels[e], pixels) << "eye " << e << ", frame " << frame;
    }
  }
  for (int e = 0; e < 2; ++e) EXPECT_LT(maxDifference(renderer.render(rig, still).eyes[e].image, target.eyes[e].image), 2e-3f * error0);
}

TEST(Temporal, StaticCameraConvergesToTheStaticImage) {
  Scene scene = builtinScene("cornell");
  StereoRig rig = smallRig(scene);
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  RenderOptions first = smallOptions(), still = smallOptions();
  first.gather.seed = 7;  // other photons: a different image
  first.photonsX = first.photonsY = 24;
  expectConvergence(renderer, rig, first, still);
}

TEST(Temporal, StaticCameraConvergesToTheStaticFoveatedImageAfterTheGazeMoved) {
  Scene scene = builtinScene("cornell");
  StereoRig rig = smallRig(scene);
  MaskParams params = maskParamsForRig(rig);
  params.tanPerPixel *= 9.0f;  // a coarse pixel: the headset's falloff on a small image
  params.acuity.gazeMarginDeg = 3.0f;
  FoveationMask mask = generateFoveationMask(params);
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  RenderOptions first = smallOptions(), still = smallOptions();
  first.foveation.mask = still.foveation.mask = &mask;
  for (auto& g : first.foveation.gaze) g[0] = 0.2f, g[1] = 0.7f;
  expectConvergence(renderer, rig, first, still);
}

// Moving the head past the caustics box's spheres uncovers wall behind them. Pixels whose surface
// the previous eye saw (Embree) keep their history, also on walls seen at grazing angles; pixels
// whose surface was hidden behind something nearer, in all nine previous pixels around it (not
// just beside a silhouette, which is ambiguous at pixel level), drop it.
TEST(Temporal, DisocclusionDropsHistoryWhereThePreviousEyeDidNotSeeTheSurface) {
  Scene scene = builtinScene("cornell-caustics");
  StereoRig rig = smallRig(scene, 128, 128);
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  const CpuBackend& backend = renderer.backendAs<CpuFrameBackend>().backend();
  RenderOptions o = smallOptions();
  o.eyes[1] = false;
  FrameResult before = renderer.render(rig, o);
  StereoRig moved = rig;
  moved.head.position = rig.head.toWorldPoint({0.4f, 0.05f, -0.5f});
  FrameResult after = renderer.render(moved, o);
  TaaView view;
  view.camera = moved.eye(Eye::Left);
  view.previousCamera = rig.eye(Eye::Left);
  view.current = after.eyes[0].image.pixels.data();
  view.inverseDepth = after.eyes[0].inverseDepth.data();
  view.history = before.eyes[0].image.pixels.data();
  view.historyInverseDepth = before.eyes[0].inverseDepth.data();
  const EyeCamera& previous = view.previousCamera;
  const EmbreeIntersector& embree = backend.intersector();
  size_t visible = 0, visibleKept = 0, hidden = 0, hiddenDropped = 0;
  for (int y = 0; y < rig.height; ++y)
    for (int x = 0; x < rig.width; ++x) {
      const bool usedHistory = resolveTemporalPixel(view, x, y).usedHistory;
      float w = view.inverseDepth[size_t(y) * rig.width + x];
      if (w == 0.0f) continue;  // background
      Vec3 world = view.camera.pointAt(x + 0.5f, y + 0.5f, w);
      float px, py;
      if (!previous.project(world, px, py) || !previous.containsPixel(px, py)) {
        EXPECT_FALSE(usedHistory) << "off the previous image: " << x << "," << y;
        continue;
      }
      Vec3 toPoint = world - previous.pose.position;
      float dist = length(toPoint);
      if (!embree.occluded({previous.pose.position, toPoint / dist}, dist * (1.0f - 2e-3f))) {
        ++visible;
        visibleKept += usedHistory ? 1 : 0;
        continue;
      }
      bool clearlyHidden = true;
      for (int j = -1; j <= 1; ++j)
        for (int i = -1; i <= 1; ++i) {
          Ray ray = previous.generateRay(std::floor(px) + i + 0.5f, std::floor(py) + j + 0.5f);
          Hit hit;
          embree.intersect(ray, INFINITY, hit);
          bool nearer = hit.valid() && previous.inverseDepthOf(ray.origin + ray.dir * hit.t) > 1.05f * previous.inverseDepthOf(world);
          clearlyHidden = clearlyHidden && nearer;
        }
      if (!clearlyHidden) continue;
      ++hidden;
      hiddenDropped += usedHistory ? 0 : 1;
    }
  ASSERT_GT(hidden, 200u) << "the move should uncover surfaces";
  EXPECT_GE(double(visibleKept), 0.99 * double(visible)) << visible - visibleKept << " of " << visible;
  EXPECT_GE(double(hiddenDropped), 0.99 * double(hidden)) << hidden - hiddenDropped << " of " << hidden;
}

// A sudden change (the image four times brighter) under a static camera: clamping to the current
// neighbourhood takes most of the new image at once; without it, 90 % of the change is missing.
TEST(Temporal, ClampingStopsGhosts) {
  Scene scene = builtinScene("cornell");
  StereoRig rig = smallRig(scene);
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  RenderOptions o = smallOptions();
  o.photonsX = o.photonsY = 256;  // little noise: the neighbourhood's range is the image's, not noise
  o.gather.density.radius = 0.1f;
  o.eyes[1] = false;
  FrameResult frame = renderer.render(rig, o);
  EyeCamera camera = rig.eye(Eye::Left);
  double ghostClamped = 0, ghostUnclamped = 0;
  for (bool clamp : {true, false}) {
    TaaHistory history;
    TaaParams params;
    params.clampToNeighbourhood = clamp;
    const EyeResult& eye = frame.eyes[0];
    Image shown;
    resolveTemporal(camera, params, eye.image, eye.inverseDepth, nullptr, history, shown);
    Image expected = eye.image;
    for (Vec3& c : expected.pixels) c *= 4.0f;
    EXPECT_EQ(resolveTemporal(camera, params, expected, eye.inverseDepth, nullptr, history, shown),
              size_t(rig.width) * rig.height);
    // The ghost: the share of the change still missing, averaged over the lit pixels.
    double ghost = 0;
    size_t lit = 0;
    for (size_t i = 0; i < expected.pixels.size(); ++i) {
      double change = 0.75 * luminance(expected.pixels[i]);
      if (change <= 0.0) continue;
      ghost += luminance(abs(shown.pixels[i] - expected.pixels[i])) / change;
      ++lit;
    }
    ASSERT_GT(lit, expected.pixels.size() / 3);
    (clamp ? ghostClamped : ghostUnclamped) = ghost / double(lit);
  }
  EXPECT_NEAR(ghostUnclamped, 1.0 - TaaParams().blend, 1e-4);
  EXPECT_LT(ghostClamped, 0.4);
}

// While TAA blends frames each frame draws new random numbers, so that the blend averages noise;
// frames that blend nothing, or a renderer told not to, draw the seed's.
TEST(Temporal, BlendedFramesDrawNewNoiseEachFrame) {
  Scene scene = builtinScene("cornell");
  StereoRig rig = smallRig(scene);
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  RenderOptions o = smallOptions();
  EXPECT_EQ(maxDifference(renderer.render(rig, o).eyes[0].image, renderer.render(rig, o).eyes[0].image), 0.0f);
  o.temporal.enabled = true;
  o.temporal.taa.blend = 1.0f;  // shows the current frame
  EXPECT_GT(maxDifference(renderer.render(rig, o).eyes[0].image, renderer.render(rig, o).eyes[0].image), 0.01f);
  renderer.setFreshNoisePerFrame(false);  // the same frame again (up to the blend's rounding)
  EXPECT_LT(maxDifference(renderer.render(rig, o).eyes[0].image, renderer.render(rig, o).eyes[0].image), 1e-5f);
}

TEST(Temporal, ResetAndNewEyeSizeStartFromTheRenderedFrame) {
  Scene scene = builtinScene("cornell");
  StereoRig rig = smallRig(scene);
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  renderer.setFreshNoisePerFrame(false);  // the TAA frame after the reset is the plain frame exactly
  RenderOptions o = smallOptions();
  RenderOptions other = o;
  other.gather.seed = 5;
  o.temporal.enabled = other.temporal.enabled = true;
  renderer.render(rig, other);
  renderer.resetHistory();
  FrameResult afterReset = renderer.render(rig, o);
  o.temporal.enabled = false;
  FrameResult plain = renderer.render(rig, o);
  EXPECT_EQ(afterReset.historyPixels[0], 0u);
  EXPECT_EQ(maxDifference(afterReset.eyes[0].image, plain.eyes[0].image), 0.0f);
  // Rendering without TAA forgets the history too; so does a new eye size.
  o.temporal.enabled = true;
  EXPECT_EQ(renderer.render(rig, o).historyPixels[1], 0u);
  EXPECT_GT(renderer.render(rig, o).historyPixels[1], 0u);
  StereoRig bigger = smallRig(scene, 96, 88);
  EXPECT_EQ(renderer.render(bigger, o).historyPixels[0], 0u);
  // An eye left out for a frame comes back without its (stale) history.
  EXPECT_GT(renderer.render(bigger, o).historyPixels[1], 0u);
  o.eyes[1] = false;
  renderer.render(bigger, o);
  o.eyes[1] = true;
  FrameResult back = renderer.render(bigger, o);
  EXPECT_EQ(back.historyPixels[1], 0u);
  EXPECT_GT(back.historyPixels[0], 0u);
  // Out-of-range parameters are refused.
  o.temporal.taa.blend = 0.0f;
  EXPECT_THROW(renderer.render(rig, o), Error);
  o.temporal.taa.blend = 0.5f;
  o.temporal.taa.depthTolerance = 0.0f;
  EXPECT_THROW(renderer.render(rig, o), Error);
}

}  // namespace
}  // namespace pvr
