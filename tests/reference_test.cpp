// The converged reference (reference/progressive_reference.h) and the error metrics it is read
// with (image/image_compare.h): the metrics' analytic values, the radius schedule, and the
// reference's convergence at the expected power of the pass count on the white furnace (against
// its analytic radiance) and the Cornell box (against a long independent reference).
#include <gtest/gtest.h>

#include <cmath>

#include "pvr/cpu/cpu_frame_backend.h"
#include "pvr/image/image_compare.h"
#include "pvr/image/image_io.h"
#include "pvr/reference/progressive_reference.h"
#include "pvr/scene/scene.h"
#include "pvr/util/error.h"
#include "test_scenes.h"

namespace pvr {
namespace {

Image constantImage(int w, int h, Vec3 v) {
  Image image(w, h);
  for (Vec3& p : image.pixels) p = v;
  return image;
}

TEST(ReferenceError, IdenticalImagesHaveNoError) {
  Image a(40, 30);
  for (size_t i = 0; i < a.pixels.size(); ++i) a.pixels[i] = Vec3(float(i % 7) * 0.1f, float(i % 11) * 0.05f, 0.3f);
  ReferenceError e = compareToReference(a, a);
  EXPECT_EQ(e.relMse, 0.0);
  EXPECT_NEAR(e.ssim, 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(e.meanRatio, 1.0);
  EXPECT_TRUE(std::isinf(e.psnr));
  EXPECT_EQ(e.pixels, a.pixels.size());
}

TEST(ReferenceError, RelativeMseAndMeanRatioOfAScaledImage) {
  Image reference(16, 16);
  for (size_t i = 0; i < reference.pixels.size(); ++i) reference.pixels[i] = Vec3(0.05f + 0.01f * float(i % 50));
  Image scaled = reference;
  for (Vec3& p : scaled.pixels) p *= 1.1f;
  double expected = 0;
  for (const Vec3& p : reference.pixels) expected += 0.01 * double(p.x) * p.x / (double(p.x) * p.x + 0.01);
  expected /= double(reference.pixels.size());
  ReferenceError e = compareToReference(scaled, reference);
  EXPECT_NEAR(e.relMse, expected, 1e-6 * expected);
  EXPECT_NEAR(e.meanRatio, 1.1, 1e-6);
  EXPECT_NEAR(relativeMse(scaled, reference), expected, 1e-6 * expected);
}

// relativeMse alone (the controller bench's per-frame error) over masked-in pixels only: the
// masked-out half is off by 100x and must not count.
TEST(ReferenceError, RelativeMseAloneCountsOnlyTheMaskedInPixels) {
  Image reference(8, 8), test(8, 8);
  std::vector<uint8_t> mask(64, 0);
  for (size_t i = 0; i < 64; ++i) {
    reference.pixels[i] = Vec3(0.2f);
    mask[i] = i < 32;
    test.pixels[i] = Vec3(i < 32 ? 0.3f : 20.0f);
  }
  const double expected = 0.01 / (0.04 + 0.01);
  EXPECT_NEAR(relativeMse(test, reference, mask), expected, 1e-6);
  EXPECT_NEAR(compareToReference(test, reference, mask).relMse, expected, 1e-6);
  EXPECT_EQ(relativeMse(test, reference, std::vector<uint8_t>(64, 0)), 0.0);
  EXPECT_THROW(relativeMse(Image(4, 4), reference), Error);
}

// Two constant images: no variance, so SSIM is its luminance term (2 a b + C1) / (a^2 + b^2 + C1)
// of the displayed values.
TEST(ReferenceError, SsimOfConstantImagesIsItsLuminanceTerm) {
  const float a = linearToSrgb(0.2f), b = linearToSrgb(0.3f);
  ReferenceError e = compareToReference(constantImage(20, 20, Vec3(0.2f)), constantImage(20, 20, Vec3(0.3f)));
  const double c1 = 1e-4, expected = (2.0 * a * b + c1) / (double(a) * a + double(b) * b + c1);
  EXPECT_NEAR(e.ssim, expected, 1e-5);
}

TEST(ReferenceError, SsimFallsWithNoise) {
  Image reference(48, 48);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) reference.at(x, y) = Vec3(((x / 8 + y / 8) % 2) ? 0.6f : 0.1f);
  double last = 1.0;
  for (float amplitude : {0.05f, 0.3f, 1.5f}) {
    Image noisy = reference;
    uint32_t state = 12345;
    for (Vec3& p : noisy.pixels) {
      state = state * 1664525u + 1013904223u;
      p *= 1.0f + amplitude * (float(state >> 8) / 16777216.0f - 0.5f);
    }
    double ssim = compareToReference(noisy, reference).ssim;
    EXPECT_LT(ssim, last) << amplitude;
    last = ssim;
  }
  EXPECT_LT(last, 0.9);
  EXPECT_THROW(compareToReference(Image(4, 4), reference), Error);
}

TEST(ProgressiveReference, RadiusFollowsTheKnausZwickerRule) {
  Scene scene = builtinScene("cornell");
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  RenderOptions options;
  options.gather.density.radius = 0.08f;
  ReferenceSettings settings;
  settings.alpha = 0.7f;
  ProgressiveReference reference(renderer, scene.rig, options, settings);
  double r2 = 0.08 * 0.08;
  for (int i = 0; i < 50; ++i) {
    EXPECT_NEAR(reference.radiusOfPass(i), std::sqrt(r2), 1e-6) << i;
    r2 *= (i + 1 + 0.7) / (i + 2.0);
  }
  settings.alpha = 1.0f;
  EXPECT_THROW(ProgressiveReference(renderer, scene.rig, options, settings), Error);
}

// relMSE of an eye's average after each of `checkpoints` passes against `truth`, summed over
// independent seeds (the photon noise of one map is shared by every pixel, so one run's error
// is itself noisy).
std::vector<double> errorsAtPasses(const Scene& scene, const StereoRig& rig, RenderOptions options, const std::vector<int>& checkpoints,
                                   const Image& truth, int seeds) {
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  std::vector<double> errors(checkpoints.size(), 0.0);
  for (int s = 0; s < seeds; ++s) {
    options.gather.seed = 1000u + uint32_t(s);
    ProgressiveReference reference(renderer, rig, options);
    for (size_t c = 0; c < checkpoints.size(); ++c) {
      while (reference.passes() < checkpoints[c]) reference.addPass();
      errors[c] += compareToReference(reference.image(Eye::Left), truth).relMse / seeds;
    }
  }
  return errors;
}

// Knaus-Zwicker: variance O(n^-alpha), squared bias O(n^(2 alpha - 2)); with alpha = 0.7 the
// error falls as n^-0.6 .. n^-0.7, and faster where the 1/n of the shadow rays dominates.
void expectConvergenceExponent(const std::vector<int>& n, const std::vector<double>& errors, const char* what) {
  for (size_t i = 1; i < n.size(); ++i) {
    double exponent = std::log(errors[i] / errors[i - 1]) / std::log(double(n[i]) / n[i - 1]);
    std::printf("%s: relMSE %.3g after %d passes, %.3g after %d: exponent %.3f\n", what, errors[i - 1], n[i - 1], errors[i],
                n[i], exponent);
    EXPECT_LT(exponent, -0.45) << what << " from " << n[i - 1] << " to " << n[i] << " passes: " << errors[i - 1] << " -> " << errors[i];
    EXPECT_GT(exponent, -1.15) << what << " from " << n[i - 1] << " to " << n[i] << " passes: " << errors[i - 1] << " -> " << errors[i];
  }
}

// Away from the cube's edges the furnace's radiance is uniform, so the fixed radius has no bias
// there and the error is the passes' variance alone: O(n^-alpha) exactly (each pass's variance
// grows as 1 / r_i^2 ~ i^(1 - alpha)). The edges' bias is the Cornell box test's.
TEST(ProgressiveReference, ConvergesToTheFurnacesAnalyticRadianceAtTheExpectedRate) {
  const float rho = 0.5f, le = 1.0f, radius = 0.12f;
  Scene scene = test::furnaceBox(rho, le);
  StereoRig rig = scene.rig;
  rig.width = rig.height = 32;
  RenderOptions options;
  options.eyes[1] = false;
  options.photonsX = options.photonsY = 48;
  options.maxPhotonDepth = 16;  // rho^16 of the power is lost: negligible
  options.gather.density.radius = radius;
  // The photon map alone: with shadow rays, the area-light samples of the walls meeting at an
  // edge have unbounded variance (1 / d^2 with d -> 0), heavy-tailed fireflies no pass count tames.
  options.gather.mode = ShadingMode::PhotonMapOnly;
  const Image truth = constantImage(32, 32, Vec3(le / (1.0f - rho)));
  // Pixels whose whole footprint sees a wall further than 2 r from its edges (the cube is +-0.5).
  const EyeCamera camera = rig.eye(Eye::Left);
  std::vector<uint8_t> interior(truth.pixels.size(), 1);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x)
      for (float cx : {0.0f, 1.0f})
        for (float cy : {0.0f, 1.0f}) {
          Ray ray = camera.generateRay(float(x) + cx, float(y) + cy);
          float t = 1e30f;
          for (int a = 0; a < 3; ++a)
            if (ray.dir[a] != 0.0f) t = std::min(t, ((ray.dir[a] > 0 ? 0.5f : -0.5f) - ray.origin[a]) / ray.dir[a]);
          Vec3 p = ray.origin + ray.dir * t;
          int near = 0;
          for (int a = 0; a < 3; ++a) near += std::fabs(p[a]) > 0.5f - 2 * radius;
          if (near > 1) interior[size_t(y) * 32 + x] = 0;
        }
  size_t kept = 0;
  for (uint8_t k : interior) kept += k;
  ASSERT_GT(kept, 100u);
  const std::vector<int> passes = {4, 16, 64};
  std::vector<double> errors(passes.size(), 0.0);
  double estimated = 0;
  const int seeds = 2;
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  for (int s = 0; s < seeds; ++s) {
    options.gather.seed = 1000u + uint32_t(s);
    ProgressiveReference reference(renderer, rig, options);
    for (size_t c = 0; c < passes.size(); ++c) {
      while (reference.passes() < passes[c]) reference.addPass();
      errors[c] += compareToReference(reference.image(Eye::Left), truth, interior).relMse / seeds;
    }
    estimated += reference.estimatedRelMse(Eye::Left, interior) / seeds;
  }
  // With no bias, the passes' spread estimates the whole error.
  EXPECT_GT(estimated, 0.5 * errors.back());
  EXPECT_LT(estimated, 2.0 * errors.back());
  for (size_t i = 1; i < passes.size(); ++i) {
    double exponent = std::log(errors[i] / errors[i - 1]) / std::log(double(passes[i]) / passes[i - 1]);
    std::printf("furnace interior: relMSE %.3g after %d passes, %.3g after %d: exponent %.3f (expected -0.7)\n",
                errors[i - 1], passes[i - 1], errors[i], passes[i], exponent);
    EXPECT_NEAR(exponent, -0.7, 0.2) << "from " << passes[i - 1] << " to " << passes[i] << " passes: " << errors[i - 1]
                                     << " -> " << errors[i];
  }
}

TEST(ProgressiveReference, ConvergesOnTheCornellBoxAtTheExpectedRate) {
  Scene scene = builtinScene("cornell");
  StereoRig rig = scene.rig;
  rig.width = 24, rig.height = 27;
  RenderOptions options;
  options.eyes[1] = false;
  options.photonsX = options.photonsY = 64;
  options.gather.density.radius = 0.08f;
  Image truth;
  {
    FrameRenderer renderer = makeCpuFrameRenderer(scene);
    RenderOptions long_ = options;
    long_.gather.seed = 7;  // independent of the runs measured
    long_.photonsX = long_.photonsY = 256;
    ProgressiveReference reference(renderer, rig, long_);
    for (int i = 0; i < 256; ++i) reference.addPass();
    truth = reference.image(Eye::Left);
  }
  const std::vector<int> passes = {4, 16, 64};
  std::vector<double> errors = errorsAtPasses(scene, rig, options, passes, truth, 2);
  expectConvergenceExponent(passes, errors, "cornell");
}

}  // namespace
}  // namespace pvr
