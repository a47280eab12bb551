// The spatio-temporal denoiser (denoise/svgf.h) on synthetic frames whose answer is known: a
// constant signal stays constant, a noise-free one comes back unchanged once its history is long,
// surfaces of another depth or normal never blend, noise falls while the mean stays, a moving head
// keeps its history and a sharp pattern under it stays sharp, foveated taps land only on the
// samples' spacing, background shows the rendered image, and a reusing right eye shares the left
// eye's filter.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "pvr/cpu/cpu_frame_backend.h"
#include "pvr/denoise/host_denoiser.h"
#include "pvr/image/image_compare.h"
#include "pvr/photon/density.h"
#include "pvr/reference/progressive_reference.h"
#include "pvr/scene/scene.h"
#include "pvr/util/error.h"

namespace pvr {
namespace {

// A frame of a plane facing the eye: the camera at the origin looking down -Z, every pixel at
// `depth` with normal +Z, its radiance = albedo * (direct + indirect irradiance).
struct SyntheticFrame {
  EyeCamera camera;
  std::vector<Vec3> image, direct, albedo, normal;
  std::vector<float> inverseDepth, sampleSpacing;

  SyntheticFrame(int w, int h, float depth = 2.0f) {
    camera.width = w, camera.height = h;
    camera.fov = {-0.5f, 0.5f, 0.5f, -0.5f};
    const size_t n = size_t(w) * h;
    image.assign(n, Vec3(0.0f)), direct.assign(n, Vec3(0.0f)), albedo.assign(n, Vec3(1.0f));
    normal.assign(n, Vec3(0, 0, 1));
    inverseDepth.assign(n, 1.0f / depth);
  }
  size_t at(int x, int y) const { return size_t(y) * camera.width + x; }
  void set(int x, int y, Vec3 a, Vec3 directIrradiance, Vec3 indirectIrradiance) {
    albedo[at(x, y)] = a;
    direct[at(x, y)] = a * directIrradiance;
    image[at(x, y)] = a * (directIrradiance + indirectIrradiance);
  }
  DenoiseInputs inputs() const {
    DenoiseInputs in;
    in.image = image.data(), in.direct = direct.data(), in.albedo = albedo.data(), in.normal = normal.data();
    in.inverseDepth = inverseDepth.data();
    in.sampleSpacing = sampleSpacing.empty() ? nullptr : sampleSpacing.data();
    return in;
  }
};

Vec3 checker(int x, int y) { return ((x / 3 + y / 3) & 1) ? Vec3(0.8f, 0.7f, 0.6f) : Vec3(0.2f, 0.25f, 0.3f); }

// Mean absolute difference of luminance over b's mean, over pixels x0 <= x < x1, y0 <= y < y1
// (by default all of them).
struct Window {
  int x0 = 0, y0 = 0, x1 = 1 << 30, y1 = 1 << 30;
};
double compareImages(const Image& a, const Image& b, Window window = {}) {
  double diff = 0, level = 0;
  for (int y = window.y0; y < std::min(window.y1, b.height); ++y)
    for (int x = window.x0; x < std::min(window.x1, b.width); ++x) {
      const size_t i = size_t(y) * b.width + x;
      diff += std::fabs(double(luminance(a.pixels[i])) - luminance(b.pixels[i])), level += luminance(b.pixels[i]);
    }
  return diff / level;
}

double maxRelativeError(const Image& out, const std::vector<Vec3>& expected) {
  double worst = 0;
  for (size_t i = 0; i < expected.size(); ++i)
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::fabs(double(out.pixels[i][c]) - expected[i][c]) / std::max(1e-6, double(expected[i][c])));
  return worst;
}

// Also at the magnitudes of physical units (a sun: 1e6) and of a dim scene (1e-6).
// The default filter, and the photon-map signal's later passes on a quarter of the pixels.
DenoiseParams quarterPhotonPasses(DenoiseParams params = DenoiseParams()) {
  params.quarterPhotonPasses = true;
  return params;
}

TEST(Denoise, ConstantIrradianceStaysConstantUnderATexture) {
  for (const DenoiseParams& params : {DenoiseParams(), quarterPhotonPasses()})
    for (float magnitude : {1.0f, 1e6f, 1e-6f}) {
      SyntheticFrame f(64, 48);
      for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 64; ++x) f.set(x, y, checker(x, y), Vec3(0.5f) * magnitude, Vec3(0.3f, 0.2f, 0.1f) * magnitude);
      HostDenoiser denoiser;
      Image out;
      for (int frame = 0; frame < 6; ++frame) {
        denoiser.denoise(Eye::Left, f.camera, params, f.inputs(), out);
        EXPECT_LT(maxRelativeError(out, f.image), 1e-5)
            << "magnitude " << magnitude << ", frame " << frame << ", quarter " << params.quarterPhotonPasses;
      }
    }
}

TEST(Denoise, NoiseFreeImageIsUnchangedOnceItsHistoryIsLong) {
  SyntheticFrame f(64, 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const float e = 0.5f + 0.4f * std::sin(float(x) / 7.0f) * std::cos(float(y) / 5.0f);
      f.set(x, y, checker(x, y), Vec3(e), Vec3(0.2f * e + 0.05f));
      if (x > 40 && y > 20 && y < 30) f.direct[f.at(x, y)] = Vec3(0.0f), f.image[f.at(x, y)] = checker(x, y) * 0.1f;  // a hard shadow
    }
  // The first frames (short history, variance from the neighbourhood) blur; their share of the
  // history falls by 0.8 per frame, and a zero temporal variance stops every tap that differs
  // (also the quarter passes' interpolation: the shadow steps the photon-map signal too).
  for (const DenoiseParams& params : {DenoiseParams(), quarterPhotonPasses()}) {
    HostDenoiser denoiser;
    Image out;
    for (int frame = 0; frame < 40; ++frame) denoiser.denoise(Eye::Left, f.camera, params, f.inputs(), out);
    EXPECT_LT(maxRelativeError(out, f.image), 2e-3) << "quarter " << params.quarterPhotonPasses;
  }
}

// Left half: one surface with noise; right half: another surface (farther, or turned), as bright
// or 1000 times brighter. The left half must come out the same either way: no left pixel takes
// any of the right's light, whatever the luminance test says.
// Under quarter photon passes the edge also lies between an even and an odd column (odd pixels
// interpolate from both sides).
void expectNoBlending(const char* what, float rightDepth, Vec3 rightNormal, float sigmaLuminance, bool quarter = false,
                      int edge = 24) {
  DenoiseParams params;
  params.sigmaLuminance = sigmaLuminance;
  params.quarterPhotonPasses = quarter;
  Image left[2];
  for (int run = 0; run < 2; ++run) {
    SyntheticFrame f(48, 32);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> noise(0.5f, 1.5f);
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 48; ++x) {
        const bool right = x >= edge;
        const float value = (right && run == 1 ? 1000.0f : 1.0f) * noise(rng);
        f.set(x, y, Vec3(0.5f), Vec3(value), Vec3(0.1f * value));
        if (right) f.inverseDepth[f.at(x, y)] = 1.0f / rightDepth, f.normal[f.at(x, y)] = rightNormal;
      }
    HostDenoiser denoiser;
    for (int frame = 0; frame < 3; ++frame) denoiser.denoise(Eye::Left, f.camera, params, f.inputs(), left[run]);
  }
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < edge; ++x)
      ASSERT_EQ(left[0].pixels[size_t(y) * 48 + x], left[1].pixels[size_t(y) * 48 + x])
          << what << " at " << x << "," << y << ", quarter " << quarter << ", edge " << edge;
}

TEST(Denoise, SurfacesOfAnotherDepthOrNormalNeverBlend) {
  for (float sigma : {4.0f, 1e6f})  // the default luminance test, and none
    for (int quarter = 0; quarter < 2; ++quarter)
      for (int edge : {24, 25}) {
        expectNoBlending("depth edge", 2.5f, Vec3(0, 0, 1), sigma, quarter, edge);
        expectNoBlending("small depth step", 2.1f, Vec3(0, 0, 1), sigma, quarter, edge);
        expectNoBlending("normal edge", 2.0f, Vec3(1, 0, 0), sigma, quarter, edge);
        expectNoBlending("crease", 2.0f, normalize(Vec3(0.5f, 0, 0.866f)), sigma, quarter, edge);
      }
}

TEST(Denoise, NoiseFallsAndTheMeanStays) {
  SyntheticFrame f(96, 96);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> noise(0.0f, 2.0f);
  for (int y = 0; y < 96; ++y)
    for (int x = 0; x < 96; ++x) f.set(x, y, checker(x, y), Vec3(0.5f * noise(rng)), Vec3(0.2f * noise(rng)));
  HostDenoiser denoiser;
  Image out;
  denoiser.denoise(Eye::Left, f.camera, DenoiseParams(), f.inputs(), out);
  // Error against the noise-free answer, albedo * 0.7.
  double before = 0, after = 0, meanIn = 0, meanOut = 0;
  for (int y = 0; y < 96; ++y)
    for (int x = 0; x < 96; ++x) {
      const double truth = luminance(checker(x, y) * 0.7f);
      const double in = luminance(f.image[f.at(x, y)]), o = luminance(out.pixels[f.at(x, y)]);
      before += (in - truth) * (in - truth), after += (o - truth) * (o - truth);
      meanIn += in, meanOut += o;
    }
  EXPECT_LT(after, before / 10.0);
  EXPECT_NEAR(meanOut / meanIn, 1.0, 0.02);
}

TEST(Denoise, AMovingHeadKeepsItsHistoryAndADisocclusionDropsIt) {
  SyntheticFrame f(64, 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) f.set(x, y, checker(x, y), Vec3(0.5f), Vec3(0.2f));
  HostDenoiser denoiser;
  Image out;
  EXPECT_EQ(denoiser.denoise(Eye::Left, f.camera, DenoiseParams(), f.inputs(), out), 0u);
  SyntheticFrame moved = f;
  moved.camera.pose.position = Vec3(0.01f, 0.0f, 0.0f);  // 1 cm right: the plane moves about 0.3 px
  const size_t used = denoiser.denoise(Eye::Left, moved.camera, DenoiseParams(), moved.inputs(), out);
  EXPECT_GT(used, size_t(64 * 62));  // all but the column that came into view
  SyntheticFrame nearer = f;
  for (float& w : nearer.inverseDepth) w = 1.0f / 1.5f;  // another surface in front
  EXPECT_EQ(denoiser.denoise(Eye::Left, nearer.camera, DenoiseParams(), nearer.inputs(), out), 0u);
}

// A noise-free pattern fixed to the plane while the head slides 0.37 px a frame: the error of the
// denoised frame (inner pixels, after 30 frames) with the history read by Catmull-Rom, and with
// bilinear reads (which blur the history by a different amount every frame).
double slidingPatternError(bool bicubicHistory, int iterations) {
  const int w = 64, h = 48;
  DenoiseParams params;
  params.iterations = iterations;
  params.bicubicHistory = bicubicHistory;
  HostDenoiser denoiser;
  Image out;
  SyntheticFrame f(w, h);
  const float pixelWidth = 2.0f * 2.0f * std::tan(0.5f) / float(w);  // at depth 2
  for (int frame = 0; frame < 30; ++frame) {
    f.camera.pose.position = Vec3(0.37f * pixelWidth * float(frame), 0.0f, 0.0f);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const float worldX = f.camera.pose.position.x + 2.0f * f.camera.localDirection(float(x) + 0.5f, 0.0f).x;
        const float e = 0.5f + 0.4f * std::sin(worldX / pixelWidth * (2.0f * kPi / 8.0f)) + 0.02f * float(y % 7);
        f.set(x, y, Vec3(0.5f), Vec3(e), Vec3(0.2f * e));
      }
    denoiser.denoise(Eye::Left, f.camera, params, f.inputs(), out);
  }
  Image expected(w, h);
  expected.pixels = f.image;
  // Inner pixels: the columns that came into view lately have short histories.
  return compareImages(out, expected, {4, 4, w - 16, h - 4});
}

TEST(Denoise, AMovingHeadsHistoryStaysSharp) {
  // The accumulation alone (no a-trous pass), then the whole filter: its luminance test reads the
  // accumulated variance, which a resampled history must not inflate where the signal is sharp.
  for (int iterations : {0, 5}) {
    const double bicubic = slidingPatternError(true, iterations), bilinear = slidingPatternError(false, iterations);
    std::printf("sliding pattern, %d a-trous passes: mean relative error %.4f with Catmull-Rom history, %.4f bilinear\n",
                iterations, bicubic, bilinear);
    EXPECT_LT(bicubic, iterations ? 0.12 : 0.04);
    EXPECT_LT(bicubic, 0.5 * bilinear);
  }
}

TEST(Denoise, FoveatedTapsLandOnTheSampleSpacing) {
  // Samples every 4 pixels carry the signal; the pixels between them hold a value 100 times
  // larger. With the spacing given, a sample's taps never read between samples.
  SyntheticFrame f(64, 64);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> noise(0.5f, 1.5f);
  float sampleMax = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const bool sample = x % 4 == 0 && y % 4 == 0;
      const float v = (sample ? 1.0f : 100.0f) * noise(rng);
      f.set(x, y, Vec3(1.0f), Vec3(v), Vec3(0.0f));
      if (sample) sampleMax = std::max(sampleMax, v);
    }
  f.sampleSpacing.assign(64 * 64, 4.0f);
  HostDenoiser denoiser;
  Image out;
  denoiser.denoise(Eye::Left, f.camera, DenoiseParams(), f.inputs(), out);
  for (int y = 0; y < 64; y += 4)
    for (int x = 0; x < 64; x += 4) ASSERT_LE(out.pixels[f.at(x, y)].x, sampleMax * 1.0001f) << x << "," << y;
  // Without the spacing the same taps blend the larger values in.
  f.sampleSpacing.clear();
  HostDenoiser fullResolution;
  fullResolution.denoise(Eye::Left, f.camera, DenoiseParams(), f.inputs(), out);
  EXPECT_GT(out.pixels[f.at(32, 32)].x, sampleMax * 2.0f);
}

// A light seen on the same plane as a noisy dim surface (the Cornell box's ceiling lamp): what was
// emitted is not filtered, so the lamp keeps its exact radiance and its edge.
TEST(Denoise, EmittedLightIsLeftAsItWas) {
  SyntheticFrame f(64, 48);
  std::vector<Vec3> emitted(64 * 48, Vec3(0.0f));
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> noise(0.0f, 2.0f);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      const bool lamp = x >= 24 && x < 40 && y >= 16 && y < 32;
      f.set(x, y, Vec3(0.78f), Vec3(0.4f * noise(rng)), Vec3(0.3f * noise(rng)));
      if (!lamp) continue;
      emitted[f.at(x, y)] = Vec3(17.0f, 12.0f, 4.0f);
      f.direct[f.at(x, y)] += emitted[f.at(x, y)];
      f.image[f.at(x, y)] += emitted[f.at(x, y)];
    }
  DenoiseInputs in = f.inputs();
  in.emitted = emitted.data();
  HostDenoiser denoiser;
  Image out;
  for (int frame = 0; frame < 4; ++frame) {
    denoiser.denoise(Eye::Left, f.camera, DenoiseParams(), in, out);
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 64; ++x) {
        const size_t i = f.at(x, y);
        const Vec3 reflected = out.pixels[i] - emitted[i];
        ASSERT_GE(reflected.x, 0.0f) << x << "," << y;
        ASSERT_LT(reflected.x, 2.0f) << "lamp light leaked into " << x << "," << y;
      }
  }
}

// Still frames (refinement) average with 1 / n: the error against the noise-free signal falls as
// the frames add up, well below what the moving head's weights (alpha 0.2) leave.
TEST(Denoise, StillFramesAverageTowardsTheNoiseFreeSignal) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> noise(0.0f, 2.0f);
  double error[2] = {0, 0};
  for (int refine = 0; refine < 2; ++refine) {
    HostDenoiser denoiser;
    Image out;
    for (int frame = 0; frame < 120; ++frame) {
      SyntheticFrame f(48, 48);
      for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 48; ++x) f.set(x, y, checker(x, y), Vec3(0.5f * noise(rng)), Vec3(0.2f * noise(rng)));
      denoiser.denoise(Eye::Left, f.camera, DenoiseParams(), f.inputs(), out, refine ? frame : 0);
    }
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 48; ++x) {
        const double d = luminance(out.pixels[size_t(y) * 48 + x] - checker(x, y) * 0.7f) / luminance(checker(x, y) * 0.7f);
        error[refine] += d * d;
      }
  }
  std::printf("rms relative error after 120 frames: moving weights %.4f, refining %.4f\n", std::sqrt(error[0] / 2304),
              std::sqrt(error[1] / 2304));
  EXPECT_LT(error[1], 0.25 * error[0]);  // squared errors; measured 0.14
}

TEST(Denoise, WithoutGuidesTheWholeImageIsOneSignal) {
  SyntheticFrame f(32, 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) f.set(x, y, Vec3(0.6f), Vec3(0.5f), Vec3(0.25f));
  DenoiseInputs in;
  in.image = f.image.data();
  in.inverseDepth = f.inverseDepth.data();
  HostDenoiser denoiser;
  Image out;
  for (int frame = 0; frame < 3; ++frame) {  // also with a history of one signal
    denoiser.denoise(Eye::Left, f.camera, DenoiseParams(), in, out, frame);
    EXPECT_LT(maxRelativeError(out, f.image), 1e-5) << "frame " << frame;
  }
}

// A noisy frame of a checker-textured plane: the same inputs for both eyes of the reuse tests.
SyntheticFrame noisyPlane(int w, int h, unsigned seed) {
  SyntheticFrame f(w, h);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> noise(0.0f, 2.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) f.set(x, y, checker(x, y), Vec3(0.5f * noise(rng)), Vec3(0.2f * noise(rng)));
  return f;
}

// A right eye's inputs under stereo reuse: `own`, with per pixel the left pixel reused and the left
// eye's (frame `leftFrame`) normals and denoised image.
DenoiseInputs reusingRightEye(DenoiseInputs own, const std::vector<uint32_t>& reusedFrom, const SyntheticFrame& leftFrame,
                              const Image& leftDenoised) {
  own.reusedFrom = reusedFrom.data();
  own.sourceNormal = leftFrame.normal.data();
  own.sourceDenoised = leftDenoised.pixels.data();
  return own;
}

// Stereo reuse: a right eye whose left half took the left eye's shading denoises that half once,
// in the left eye. With the same inputs as the left eye its pixels come out bit for bit as the left
// eye's (the reused pixels' filter levels are the left eye's), whatever its reused pixels rendered
// themselves; and next frame, shaded by itself, it carries the left eye's history on.
TEST(Denoise, ReusedPixelsShareTheLeftEyesFilterAndHistory) {
  // Also where the direct signal stops before the photon map's (its last level, kept by the left
  // eye, is read by the right eye's neighbours at the later passes).
  // And under quarter photon passes, whose reused taps read the left eye's even pixels.
  DenoiseParams directTwoPasses;
  directTwoPasses.directIterations = 2;
  for (const DenoiseParams& params : {DenoiseParams(), directTwoPasses, quarterPhotonPasses(directTwoPasses)}) {
    SCOPED_TRACE("direct signal's passes " + std::to_string(params.directIterations) + ", quarter " +
                 std::to_string(params.quarterPhotonPasses));
    const int w = 64, h = 48;
    HostDenoiser denoiser;
    Image left, right;
    SyntheticFrame f = noisyPlane(w, h, 21);
    SyntheticFrame rendered = f;  // the right eye's own rendering, 1000x off where it reused
    std::vector<uint32_t> reusedFrom(size_t(w) * h, kNotReused);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w / 2; ++x) {
        reusedFrom[f.at(x, y)] = uint32_t(f.at(x, y));
        rendered.image[f.at(x, y)] *= 1000.0f, rendered.direct[f.at(x, y)] *= 1000.0f;
      }
    DenoiseInputs leftIn = f.inputs();
    leftIn.keepLevels = true;
    denoiser.denoise(Eye::Left, f.camera, params, leftIn, left);
    const DenoiseInputs rightIn = reusingRightEye(rendered.inputs(), reusedFrom, f, left);
    EXPECT_EQ(denoiser.denoise(Eye::Right, f.camera, params, rightIn, right), 0u);
    for (size_t i = 0; i < left.pixels.size(); ++i) ASSERT_EQ(right.pixels[i], left.pixels[i]) << "pixel " << i;

    // Next frame nothing is reused: every right pixel keeps a history (the reused ones the left
    // eye's) and the two eyes stay alike to the bit.
    SyntheticFrame second = noisyPlane(w, h, 22);
    denoiser.denoise(Eye::Left, f.camera, params, second.inputs(), left);
    EXPECT_EQ(denoiser.denoise(Eye::Right, f.camera, params, second.inputs(), right), size_t(w) * h);
    for (size_t i = 0; i < left.pixels.size(); ++i) ASSERT_EQ(right.pixels[i], left.pixels[i]) << "pixel " << i;

    // The left eye must have kept its levels for a reusing right eye (this frame's left eye did
    // not), and have filtered the same pixels (the last case: the left eye's quarter passes
    // against a right eye's full ones).
    EXPECT_THROW(denoiser.denoise(Eye::Right, f.camera, params, rightIn, right), Error);
    denoiser.denoise(Eye::Left, f.camera, params, leftIn, left);
    DenoiseParams otherPixels = params;
    otherPixels.quarterPhotonPasses = !params.quarterPhotonPasses;
    EXPECT_THROW(denoiser.denoise(Eye::Right, f.camera, otherPixels, rightIn, right), Error);
  }
}

// --denoise-direct-iterations: the direct signal is filtered by the first passes only, the photon
// map's by all, each on its own. Over a moving history of frames, a frame with both signals comes
// out as the sum of the direct signal alone through that many passes and the photon map's alone
// through all of them (within rounding: the sums are taken in another order), and the direct
// signal alone comes out bit for bit as a filter of that many passes gives it.
TEST(Denoise, TheDirectSignalTakesOnlyItsPasses) {
  const int w = 64, h = 48, directPasses = 2;
  DenoiseParams split, all, fewer;
  split.directIterations = directPasses;
  fewer.iterations = fewer.directIterations = directPasses;
  HostDenoiser both, directAlone, directShort, photonMapAlone, unsplit;
  Image out, direct, directReference, photonMap, unsplitOut;
  double difference = 0;
  for (int frame = 0; frame < 4; ++frame) {
    SCOPED_TRACE("frame " + std::to_string(frame));
    const SyntheticFrame f = noisyPlane(w, h, 40 + unsigned(frame));
    SyntheticFrame onlyDirect = f, onlyPhotonMap = f;
    for (size_t i = 0; i < f.image.size(); ++i) onlyDirect.image[i] = f.direct[i], onlyPhotonMap.image[i] = f.image[i] - f.direct[i], onlyPhotonMap.direct[i] = Vec3(0.0f);
    both.denoise(Eye::Left, f.camera, split, f.inputs(), out);
    directAlone.denoise(Eye::Left, f.camera, split, onlyDirect.inputs(), direct);
    directShort.denoise(Eye::Left, f.camera, fewer, onlyDirect.inputs(), directReference);
    photonMapAlone.denoise(Eye::Left, f.camera, all, onlyPhotonMap.inputs(), photonMap);
    unsplit.denoise(Eye::Left, f.camera, all, f.inputs(), unsplitOut);
    for (size_t i = 0; i < out.pixels.size(); ++i) {
      ASSERT_EQ(direct.pixels[i], directReference.pixels[i]) << "pixel " << i;
      const Vec3 sum = direct.pixels[i] + photonMap.pixels[i];
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(out.pixels[i][c], sum[c], 1e-6f * std::max(1.0f, sum[c])) << "pixel " << i;
    }
    difference += compareImages(out, unsplitOut);
  }
  // And it is not the filter of all passes for both: the direct signal is filtered less.
  EXPECT_GT(difference / 4, 1e-3);
}

// No pass reads what neither this frame nor the history's frame wrote: with every buffer the passes
// write filled with NaN before each frame (HostDenoiser::poisonUnwritten), both eyes come out bit
// for bit as without, over frames where the right eye reuses a different third of its pixels each
// frame (its history then refers to the left eye's), with background beside the surfaces, moving
// and then refining, with the direct signal through all passes and through two.
// Under quarter photon passes also with the reused pixels one column, and then one diagonal, from
// their sources (a disparity of odd pixels: reused taps read the left eye's nearest even pixel).
TEST(Denoise, NoPassReadsWhatNoFrameWrote) {
  const int w = 48, h = 40;
  DenoiseParams directTwoPasses;
  directTwoPasses.directIterations = 2;
  struct Case {
    DenoiseParams params;
    int shiftX = 0, shiftY = 0;
  };
  for (const Case& c : {Case{DenoiseParams()}, Case{directTwoPasses}, Case{quarterPhotonPasses()},
                        Case{quarterPhotonPasses(directTwoPasses), 1, 0}, Case{quarterPhotonPasses(), 1, 1}}) {
    const DenoiseParams& params = c.params;
    HostDenoiser clean, poisoned;
    poisoned.poisonUnwritten(true);
    for (int frame = 0; frame < 12; ++frame) {
      SCOPED_TRACE("direct passes " + std::to_string(params.directIterations) + ", quarter " +
                   std::to_string(params.quarterPhotonPasses) + ", shift " + std::to_string(c.shiftX) + "," +
                   std::to_string(c.shiftY) + ", frame " + std::to_string(frame));
      SyntheticFrame f = noisyPlane(w, h, 60 + unsigned(frame));
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < 6; ++x) f.inverseDepth[f.at(x, y)] = 0.0f, f.image[f.at(x, y)] = Vec3(0.5f);  // sky
      std::vector<uint32_t> reusedFrom(size_t(w) * h, kNotReused);
      for (int y = c.shiftY; y < h; ++y)
        for (int x = 6 + c.shiftX; x < w; ++x)
          if ((x + y + frame) % 3 == 0) reusedFrom[f.at(x, y)] = uint32_t(f.at(x - c.shiftX, y - c.shiftY));
      const int still = frame < 6 ? 0 : frame - 5;
      Image out[2][2];  // [denoiser][eye]
      HostDenoiser* denoisers[2] = {&clean, &poisoned};
      for (int d = 0; d < 2; ++d) {
        DenoiseInputs leftIn = f.inputs();
        leftIn.keepLevels = true;
        denoisers[d]->denoise(Eye::Left, f.camera, params, leftIn, out[d][0], still);
        denoisers[d]->denoise(Eye::Right, f.camera, params, reusingRightEye(f.inputs(), reusedFrom, f, out[d][0]),
                              out[d][1], still);
      }
      for (int e = 0; e < 2; ++e)
        for (size_t i = 0; i < out[0][e].pixels.size(); ++i) {
          const Vec3 c = out[1][e].pixels[i];
          ASSERT_TRUE(isFinite(c)) << "eye " << e << ", pixel " << i;
          ASSERT_EQ(c, out[0][e].pixels[i]) << "eye " << e << ", pixel " << i;
        }
    }
  }
}

// Quarter photon passes: the photon-map signal's passes after the first run on the even pixels
// alone, whose taps at steps 2, 4, ... land on even pixels only. Over frames of a noisy plane with
// a farther surface beside it (its edge on an odd column), moving and then refining, the even
// pixels come out bit for bit as the full filter gives them (with each level in a buffer of its
// own, as a left eye under reuse keeps them, and with levels two apart sharing one); the odd ones,
// interpolated, stay near it and as near the noise-free answer. A right eye reusing a third of its
// pixels one column and one row off (reused taps read the left eye's nearest even pixel) stays
// near the full filter's right eye too.
TEST(Denoise, QuarterPhotonPassesAreTheFullFilterOnTheEvenPixels) {
  const int w = 64, h = 48;
  DenoiseParams directTwoPasses, fourPasses;
  directTwoPasses.directIterations = 2;
  fourPasses.iterations = 4, fourPasses.directIterations = 2;
  for (const DenoiseParams& params : {DenoiseParams(), directTwoPasses, fourPasses}) {
    SCOPED_TRACE("passes " + std::to_string(params.iterations) + ", direct " + std::to_string(params.directIterations));
    HostDenoiser full, quarter, fullAlone, quarterAlone;
    double oddDifference = 0, oddLevel = 0, fullError = 0, quarterError = 0, rightDifference = 0, rightLevel = 0;
    for (int frame = 0; frame < 12; ++frame) {
      const int still = frame < 8 ? 0 : frame - 7;
      SyntheticFrame f = noisyPlane(w, h, 200 + unsigned(frame));
      for (int y = 0; y < h; ++y)
        for (int x = 41; x < w; ++x) f.inverseDepth[f.at(x, y)] = 1.0f / 3.0f;
      std::vector<uint32_t> reusedFrom(size_t(w) * h, kNotReused);
      for (int y = 1; y < h; ++y)
        for (int x = 1; x < w; ++x)
          if ((x + 2 * y) % 3 == 0 && (x < 41) == (x - 1 < 41)) reusedFrom[f.at(x, y)] = uint32_t(f.at(x - 1, y - 1));
      Image out[2][2], alone[2];  // [full, quarter][eye], [full, quarter] without kept levels
      HostDenoiser* denoisers[2] = {&full, &quarter};
      HostDenoiser* alones[2] = {&fullAlone, &quarterAlone};
      for (int d = 0; d < 2; ++d) {
        DenoiseParams p = params;
        p.quarterPhotonPasses = d == 1;
        DenoiseInputs leftIn = f.inputs();
        leftIn.keepLevels = true;
        denoisers[d]->denoise(Eye::Left, f.camera, p, leftIn, out[d][0], still);
        denoisers[d]->denoise(Eye::Right, f.camera, p, reusingRightEye(f.inputs(), reusedFrom, f, out[d][0]), out[d][1],
                              still);
        alones[d]->denoise(Eye::Left, f.camera, p, f.inputs(), alone[d], still);
      }
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const size_t i = f.at(x, y);
          const double a = luminance(out[0][0].pixels[i]), b = luminance(out[1][0].pixels[i]);
          if ((x | y) % 2 == 0) {
            ASSERT_EQ(out[1][0].pixels[i], out[0][0].pixels[i]) << "frame " << frame << " at " << x << "," << y;
            ASSERT_EQ(alone[1].pixels[i], alone[0].pixels[i]) << "frame " << frame << " at " << x << "," << y;
          } else {
            oddDifference += std::fabs(b - a), oddLevel += a;
          }
          const double truth = luminance(checker(x, y) * 0.7f);
          fullError += (a - truth) * (a - truth), quarterError += (b - truth) * (b - truth);
          rightDifference += std::fabs(double(luminance(out[1][1].pixels[i])) - luminance(out[0][1].pixels[i]));
          rightLevel += luminance(out[0][1].pixels[i]);
        }
    }
    std::printf("passes %d, direct %d: odd pixels %.4f off the full filter, squared error %.4f of its, right eye %.4f off\n",
                params.iterations, params.directIterations, oddDifference / oddLevel, quarterError / fullError,
                rightDifference / rightLevel);
    EXPECT_GT(oddDifference, 0.0);  // the odd pixels are interpolated, not filtered
    EXPECT_LT(oddDifference / oddLevel, 0.01);  // 0.1 % (their first-pass output alone: several per cent)
    EXPECT_LT(quarterError, 1.05 * fullError);
    EXPECT_LT(rightDifference / rightLevel, 0.01);
  }
}

// A non-finite sample (an eye pass's NaN or +Inf) counts as black: the frames come out as with
// black there, every pixel finite, frame after frame (moving and then refining), instead of the
// filter spreading it over its footprint and the history keeping it. Also a non-finite albedo
// (demodulated by 1, as a black one).
TEST(Denoise, NonFiniteSamplesCountAsBlack) {
  const int w = 40, h = 32;
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  HostDenoiser poisoned, black;
  for (int frame = 0; frame < 8; ++frame) {
    SCOPED_TRACE("frame " + std::to_string(frame));
    SyntheticFrame bad = noisyPlane(w, h, 90 + unsigned(frame)), good = bad;
    const size_t a = bad.at(10, 10), b = bad.at(20, 12), c = bad.at(30, 20), d = bad.at(5 + frame, 25);
    bad.image[a] = Vec3(inf, 0.5f, 0.5f);  // the photon-map signal infinite
    good.image[a] = good.direct[a];
    bad.direct[b] = Vec3(nan);  // both signals non-finite
    good.direct[b] = Vec3(0.0f), good.image[b] = Vec3(0.0f);
    bad.albedo[c] = Vec3(inf);
    good.albedo[c] = Vec3(1.0f);
    bad.image[d] = bad.direct[d] = Vec3(nan, inf, 1.0f);  // a different pixel each frame
    good.image[d] = good.direct[d] = Vec3(0.0f);
    const int still = frame < 4 ? 0 : frame - 3;
    Image out, expected;
    poisoned.denoise(Eye::Left, bad.camera, DenoiseParams(), bad.inputs(), out, still);
    black.denoise(Eye::Left, good.camera, DenoiseParams(), good.inputs(), expected, still);
    for (size_t i = 0; i < out.pixels.size(); ++i) {
      ASSERT_TRUE(isFinite(out.pixels[i])) << "pixel " << i;
      ASSERT_EQ(out.pixels[i], expected.pixels[i]) << "pixel " << i;
    }
  }
}

// The same where reused pixels are far brighter than those the right eye shades itself: its own
// pixels average the left eye's bright levels (here at the a-trous passes' longer steps, beyond a
// dim reused strip that keeps them out of its own pixels' variance windows), and must take them
// exactly as the left eye's filter does (levels stored at a scale from the right eye's own pixels
// alone, as a half-precision version did, clamped them).
TEST(Denoise, ReusedPixelsFarBrighterThanTheRightEyesOwnKeepTheirValue) {
  const int w = 64, h = 48;
  HostDenoiser denoiser;
  Image left, right;
  SyntheticFrame f = noisyPlane(w, h, 23);
  std::vector<uint32_t> reusedFrom(size_t(w) * h, kNotReused);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w / 2; ++x) {
      reusedFrom[f.at(x, y)] = uint32_t(f.at(x, y));
      if (x < w / 2 - 8) f.image[f.at(x, y)] *= 1e4f, f.direct[f.at(x, y)] *= 1e4f;
    }
  DenoiseInputs leftIn = f.inputs();
  leftIn.keepLevels = true;
  denoiser.denoise(Eye::Left, f.camera, DenoiseParams(), leftIn, left);
  const DenoiseInputs rightIn = reusingRightEye(f.inputs(), reusedFrom, f, left);
  denoiser.denoise(Eye::Right, f.camera, DenoiseParams(), rightIn, right);
  for (size_t i = 0; i < left.pixels.size(); ++i) ASSERT_EQ(right.pixels[i], left.pixels[i]) << "pixel " << i;
}

// Background (nothing hit) is not filtered: it shows what the eye pass rendered, to the bit, and
// what it holds never reaches a surface beside it.
TEST(Denoise, BackgroundShowsTheRenderedImage) {
  const int w = 48, h = 40;
  Image out[2];
  for (int run = 0; run < 2; ++run) {
    SyntheticFrame f = noisyPlane(w, h, 31);
    std::vector<Vec3> emitted(size_t(w) * h, Vec3(0.0f));
    std::mt19937 rng(32 + run);
    std::uniform_real_distribution<float> sky(0.5f, 50.0f);
    for (int y = 0; y < h / 3; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = f.at(x, y);
        f.inverseDepth[i] = 0.0f, f.normal[i] = Vec3(0.0f);
        f.image[i] = f.direct[i] = emitted[i] = Vec3(sky(rng), sky(rng), sky(rng));
      }
    DenoiseInputs in = f.inputs();
    in.emitted = emitted.data();
    HostDenoiser denoiser;
    for (int frame = 0; frame < 3; ++frame) {
      denoiser.denoise(Eye::Left, f.camera, DenoiseParams(), in, out[run]);
      for (int y = 0; y < h / 3; ++y)
        for (int x = 0; x < w; ++x) ASSERT_EQ(out[run].pixels[f.at(x, y)], f.image[f.at(x, y)]) << x << "," << y;
    }
  }
  for (int y = h / 3; y < h; ++y)
    for (int x = 0; x < w; ++x) ASSERT_EQ(out[0].pixels[size_t(y) * w + x], out[1].pixels[size_t(y) * w + x]) << x << "," << y;
}

// The Cornell box through the frame pipeline at real-time settings (one sample per pixel, few
// photons): the denoised image is nearer the converged reference than the raw one, at once and more
// so as a still head's history grows, and keeps its mean.
TEST(DenoiseFrames, TheCornellBoxComesCloserToItsReference) {
  Scene scene = builtinScene("cornell");
  StereoRig rig = scene.rig;
  rig.width = 144, rig.height = 160;  // the filter's steps (up to 16 pixels) need room
  RenderOptions options;
  options.eyes[1] = false;
  options.photonsX = options.photonsY = 96;
  options.gather.density.radius = 0.05f;
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  Image truth;
  {
    RenderOptions converged = options;
    converged.gather.seed = 99;
    converged.photonsX = converged.photonsY = 256;
    ReferenceSettings centre;
    centre.boxFilter = false;  // as the real-time image samples the pixel centre
    ProgressiveReference reference(renderer, rig, converged, centre);
    for (int i = 0; i < 96; ++i) reference.addPass();
    truth = reference.image(Eye::Left);
  }
  FrameRenderer denoising = makeCpuFrameRenderer(scene);
  double raw = 0, first = 0, later = 0, rawMean = 0, denoisedMean = 0;
  for (int frame = 0; frame < 8; ++frame) {
    options.gather.seed = 1 + uint32_t(frame);  // a still head's frames differ only in their random numbers
    options.denoise.enabled = false;
    FrameResult plain = renderer.render(rig, options);
    options.denoise.enabled = true;
    FrameResult denoised = denoising.render(rig, options);
    const ReferenceError r = compareToReference(plain.eyes[0].image, truth);
    const ReferenceError d = compareToReference(denoised.eyes[0].image, truth);
    if (frame == 0) raw = r.relMse, first = d.relMse, rawMean = r.meanRatio, denoisedMean = d.meanRatio;
    later = d.relMse;
  }
  std::printf("cornell 144x160: relMSE raw %.4g, denoised %.4g (first frame), %.4g (8th); mean ratio %.4f -> %.4f\n", raw,
              first, later, rawMean, denoisedMean);
  EXPECT_LT(first, 0.5 * raw);   // measured 0.27 (1 spp, 96x96 photons, r 0.05)
  EXPECT_LT(later, 0.25 * raw);  // measured 0.16
  EXPECT_NEAR(denoisedMean / rawMean, 1.0, 0.03);
}

// A head swaying and turning for 40 frames, TAA on: a light's radiance (tens of times the
// ceiling's, inside the ceiling pixels' clamp range) used to leak into its neighbours through
// every resampling of the history and settle as a bright rim (relMSE 80x the raw frame's at 144x160). The
// emitted part is now shown as rendered and kept out of the history: TAA's frame is nearer the
// reference than the raw one, beside the light too.
TEST(DenoiseFrames, TaaOfAMovingHeadLeavesTheLightsEdgeAlone) {
  Scene scene = builtinScene("cornell");
  const StereoRig start = [&] {
    StereoRig r = scene.rig;
    r.width = 144, r.height = 160;
    return r;
  }();
  RenderOptions options;
  options.eyes[1] = false;
  options.photonsX = options.photonsY = 96;
  auto sway = [&](int frame) {
    const float phase = 2.0f * kPi * float(frame) / 180.0f, degree = kPi / 180.0f;
    StereoRig r = start;
    r.head.position = start.head.toWorldPoint({0.05f * std::sin(phase), 0.015f * std::sin(2.0f * phase), 0.0f});
    r.head.orientation = start.head.orientation * Quat::fromAxisAngle({0, 1, 0}, 12.0f * degree * std::sin(phase)) *
                         Quat::fromAxisAngle({1, 0, 0}, 3.0f * degree * std::sin(2.0f * phase));
    return r;
  };
  const int last = 40;
  Image truth;
  {
    FrameRenderer r = makeCpuFrameRenderer(scene);
    RenderOptions converged = options;
    converged.photonsX = converged.photonsY = 256;
    ReferenceSettings centre;
    centre.boxFilter = false;
    ProgressiveReference reference(r, sway(last), converged, centre);
    for (int i = 0; i < 64; ++i) reference.addPass();
    truth = reference.image(Eye::Left);
  }
  // The pixels within two of a light's edge that are not the light: where the rim was.
  std::vector<uint8_t> rim(truth.pixels.size(), 0);
  auto isLight = [&](int x, int y) { return luminance(truth.pixels[size_t(y) * start.width + x]) > 5.0f; };
  for (int y = 0; y < start.height; ++y)
    for (int x = 0; x < start.width; ++x) {
      if (isLight(x, y)) continue;
      for (int j = -2; j <= 2; ++j)
        for (int i = -2; i <= 2; ++i) {
          const int qx = x + i, qy = y + j;
          if (qx >= 0 && qy >= 0 && qx < start.width && qy < start.height && isLight(qx, qy)) rim[size_t(y) * start.width + x] = 1;
        }
    }
  auto rimError = [&](const Image& shown) {
    double sum = 0;
    size_t n = 0;
    for (size_t i = 0; i < rim.size(); ++i) {
      if (!rim[i]) continue;
      const double t = luminance(truth.pixels[i]), d = luminance(shown.pixels[i]) - t;
      sum += d * d / (t * t + 0.01), ++n;
    }
    return sum / double(std::max<size_t>(n, 1));
  };
  ASSERT_GT(std::count(rim.begin(), rim.end(), uint8_t(1)), 50);
  Image shown[2];
  for (int taa = 0; taa < 2; ++taa) {
    FrameRenderer r = makeCpuFrameRenderer(scene);
    RenderOptions o = options;
    o.temporal.enabled = taa == 1;
    for (int f = 0; f <= last; ++f) shown[taa] = r.render(sway(f), o).eyes[0].image;
  }
  const double raw = compareToReference(shown[0], truth).relMse, taa = compareToReference(shown[1], truth).relMse;
  const double rawRim = rimError(shown[0]), taaRim = rimError(shown[1]);
  std::printf("moving cornell 144x160, frame %d: relMSE raw %.4g, TAA %.4g; beside the light raw %.4g, TAA %.4g\n", last,
              raw, taa, rawRim, taaRim);
  EXPECT_LT(taa, raw);
  EXPECT_LT(taaRim, 2.0 * rawRim);
}

// A still head refines: after 60 still frames the Cornell box is much nearer its reference than
// the moving head's weights get it; a small movement then continues from the refined history
// (a small change, no pop), where a cut would jump.
TEST(DenoiseFrames, AStillHeadRefinesAndAMoveDoesNotPop) {
  Scene scene = builtinScene("cornell");
  StereoRig rig = scene.rig;
  rig.width = 144, rig.height = 160;
  RenderOptions options;
  options.eyes[1] = false;
  options.photonsX = options.photonsY = 96;
  options.gather.density.radius = 0.05f;
  options.denoise.enabled = true;
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  Image truth;
  {
    RenderOptions converged = options;
    converged.denoise.enabled = false;
    converged.gather.seed = 99;
    converged.photonsX = converged.photonsY = 256;
    ReferenceSettings centre;
    centre.boxFilter = false;
    ProgressiveReference reference(renderer, rig, converged, centre);
    for (int i = 0; i < 128; ++i) reference.addPass();
    truth = reference.image(Eye::Left);
  }
  double error[2] = {0, 0};
  Image still;
  FrameRenderer refining = makeCpuFrameRenderer(scene);
  for (int refine = 0; refine < 2; ++refine) {
    FrameRenderer other = makeCpuFrameRenderer(scene);
    FrameRenderer& r = refine ? refining : other;
    RenderOptions o = options;
    o.denoise.params.refineWhenStill = refine == 1;
    Image last;
    for (int frame = 0; frame < 60; ++frame) last = r.render(rig, o).eyes[0].image;
    EXPECT_EQ(r.stillFrames(), refine ? 59 : 0);
    // Refining, the radius shrinks by Knaus and Zwicker's rule (after 59 still frames to 0.57 of
    // the first, above its floor).
    EXPECT_EQ(r.gatherRadius(), refine ? progressiveRadius(0.05f, 59, o.denoise.params.refineAlpha) : 0.05f);
    error[refine] = compareToReference(last, truth).relMse;
    if (refine) still = last;
  }
  std::printf("cornell 144x160 after 60 still frames: relMSE %.5f with the moving head's weights, %.5f refined\n",
              error[0], error[1]);
  EXPECT_LT(error[1], 0.5 * error[0]);
  // 2 mm: beyond the stillness tolerance, a few pixels' parallax.
  StereoRig moved = rig;
  moved.head.position = rig.head.toWorldPoint({0.002f, 0.0f, 0.0f});
  const Image afterMove = refining.render(moved, options).eyes[0].image;
  EXPECT_EQ(refining.stillFrames(), 0);
  EXPECT_EQ(refining.gatherRadius(), 0.05f);
  refining.resetHistory();
  const Image afterCut = refining.render(moved, options).eyes[0].image;
  const double moveChange = compareImages(afterMove, still), cutChange = compareImages(afterCut, still);
  std::printf("change of the first moving frame: %.4f (a cut: %.4f)\n", moveChange, cutChange);
  EXPECT_LT(moveChange, 0.5 * cutChange);
}

// Under full-resolution stereo reuse the right eye's reused pixels show the left eye's denoised
// colour exactly, and the others are denoised in the right eye.
TEST(DenoiseFrames, ReusedPixelsShowTheLeftEyesDenoisedColour) {
  Scene scene = builtinScene("cornell");
  StereoRig rig = scene.rig;
  rig.width = 48, rig.height = 54;
  RenderOptions options;
  options.photonsX = options.photonsY = 64;
  options.denoise.enabled = true;
  for (StereoMode mode : {StereoMode::Gather, StereoMode::Scatter}) {
    options.stereo = mode;
    FrameRenderer renderer = makeCpuFrameRenderer(scene);
    FrameResult f = renderer.render(rig, options);
    ASSERT_TRUE(f.eyes[1].reusedFrom.has_value());
    const std::vector<uint32_t>& from = *f.eyes[1].reusedFrom;
    size_t reused = 0;
    for (size_t i = 0; i < from.size(); ++i) {
      if (from[i] == kNotReused) continue;
      ++reused;
      ASSERT_EQ(f.eyes[1].image.pixels[i], f.eyes[0].image.pixels[from[i]]) << stereoModeName(mode) << " pixel " << i;
    }
    EXPECT_GT(reused, from.size() / 2) << stereoModeName(mode);
  }
}

}  // namespace
}  // namespace pvr

namespace pvr {
namespace {

RenderOptions rollingOptions(int batches) {
  RenderOptions o;
  o.eyes[1] = false;
  o.photonsX = o.photonsY = 64;
  o.photonBatches = batches;
  o.gather.mode = ShadingMode::PhotonMapOnly;  // the image changes only with the photons
  o.temporal.enabled = true;                   // new random numbers every frame ...
  o.temporal.taa.blend = 1.0f;                 // ... and the displayed image is the rendered one
  return o;
}

StereoRig rollingRig(const Scene& scene) {
  StereoRig rig = scene.rig;
  rig.width = 48, rig.height = 54;
  return rig;
}

// With the seed's numbers in every frame, the slices together are exactly the full photon map:
// the same photons, in the same order, and the same image bit for bit.
TEST(RollingPhotons, TheSlicesOfOneSeedAreTheFullMap) {
  Scene scene = builtinScene("cornell");
  const StereoRig rig = rollingRig(scene);
  FrameRenderer whole = makeCpuFrameRenderer(scene), rolling = makeCpuFrameRenderer(scene);
  whole.setFreshNoisePerFrame(false), rolling.setFreshNoisePerFrame(false);
  for (int frame = 0; frame < 6; ++frame) {
    const FrameResult a = whole.render(rig, rollingOptions(1)), b = rolling.render(rig, rollingOptions(4));
    EXPECT_EQ(a.storedPhotons, b.storedPhotons) << "frame " << frame;
    EXPECT_EQ(a.eyes[0].image.pixels, b.eyes[0].image.pixels) << "frame " << frame;
  }
}

// With new numbers every frame, consecutive rolling maps share all but one slice: the photon
// map's image changes about sqrt(1/8) as much from frame to frame as when every photon is new,
// and its level stays.
TEST(RollingPhotons, ConsecutiveFramesShareAllButOneSlice) {
  Scene scene = builtinScene("cornell");
  const StereoRig rig = rollingRig(scene);
  double change[2] = {0, 0}, level[2] = {0, 0};
  const int batches[2] = {1, 8};
  for (int v = 0; v < 2; ++v) {
    FrameRenderer r = makeCpuFrameRenderer(scene);
    Image previous;
    for (int frame = 0; frame < 12; ++frame) {
      const Image image = r.render(rig, rollingOptions(batches[v])).eyes[0].image;
      for (const Vec3& c : image.pixels) level[v] += luminance(c);
      if (frame > 0)
        for (size_t i = 0; i < image.pixels.size(); ++i)
          change[v] += std::fabs(double(luminance(image.pixels[i])) - luminance(previous.pixels[i]));
      previous = image;
    }
  }
  std::printf("frame-to-frame change of the photon map's image: %.4g with 8 slices, %.4g with all photons new (%.3f)\n",
              change[1], change[0], change[1] / change[0]);
  EXPECT_LT(change[1], 0.6 * change[0]);
  EXPECT_GT(change[1], 0.2 * change[0]) << "a slice must be retraced every frame";
  EXPECT_NEAR(level[1] / level[0], 1.0, 0.03);
}

// A change of the photons' options retraces every slice at once: no frame mixes two settings.
TEST(RollingPhotons, AChangeOfPhotonsRetracesEverySlice) {
  Scene scene = builtinScene("cornell");
  const StereoRig rig = rollingRig(scene);
  FrameRenderer r = makeCpuFrameRenderer(scene);
  r.setFreshNoisePerFrame(false);
  RenderOptions fewer = rollingOptions(4), more = rollingOptions(4);
  fewer.temporal.enabled = more.temporal.enabled = false;  // the image as rendered, bit for bit
  more.photonsX = more.photonsY = 96;
  for (int frame = 0; frame < 3; ++frame) r.render(rig, fewer);
  FrameRenderer fresh = makeCpuFrameRenderer(scene);
  fresh.setFreshNoisePerFrame(false);
  EXPECT_EQ(r.render(rig, more).eyes[0].image.pixels, fresh.render(rig, more).eyes[0].image.pixels);
}

}  // namespace
}  // namespace pvr
