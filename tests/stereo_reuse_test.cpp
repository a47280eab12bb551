// Binocular reuse on the CPU reference: the geometry of reprojection between the eyes, the
// guarantees of both schemes (scatter never writes a point the right eye cannot see; nothing
// seen through a mirror or glass is reused; pixels not reused are exactly those of separate
// rendering), the limits (IPD 0: everything reused; a huge IPD: nothing), and the quality bar.
#include <gtest/gtest.h>

#include <cmath>

#include "pvr/foveation/mask.h"
#include "pvr/image/image_compare.h"
#include "pvr/app/options.h"
#include "pvr/cpu/cpu_frame_backend.h"
#include "pvr/render/renderer.h"
#include "pvr/util/error.h"

namespace pvr {
namespace {

StereoRig smallRig(const Scene& scene, float ipd = 0.063f) {
  StereoRig rig = scene.rig;
  rig.width = 144;
  rig.height = 160;
  rig.ipd = ipd;
  return rig;
}

RenderOptions stereoOptions(StereoMode mode, ShadingMode shading = ShadingMode::Full) {
  RenderOptions o;
  o.photonsX = o.photonsY = 96;
  o.gather.density.radius = 0.06f;
  o.gather.mode = shading;
  o.stereo = mode;
  return o;
}

size_t countReused(const EyeResult& eye) {
  size_t n = 0;
  for (uint32_t s : *eye.reusedFrom) n += s != kNotReused ? 1 : 0;
  return n;
}

// The pixels the right eye shaded itself must be those of separate rendering, bit for bit.
void expectShadedPixelsEqualSeparate(const FrameResult& reused, const FrameResult& separate) {
  const EyeResult& r = reused.eyes[1];
  ASSERT_EQ(r.reusedFrom->size(), r.image.pixels.size());
  size_t differing = 0;
  for (size_t i = 0; i < r.image.pixels.size(); ++i) {
    if (r.reusedFrom.value()[i] != kNotReused) continue;
    const Vec3 &a = r.image.pixels[i], &b = separate.eyes[1].image.pixels[i];
    differing += (a.x != b.x || a.y != b.y || a.z != b.z || r.firstPrim.value()[i] != separate.eyes[1].firstPrim.value()[i]) ? 1 : 0;
  }
  EXPECT_EQ(differing, 0u);
}

TEST(StereoReuse, ReprojectionRoundTripBetweenEyes) {
  Scene scene = builtinScene("cornell");
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  const CpuBackend& backend = renderer.backendAs<CpuFrameBackend>().backend();
  StereoRig rig = smallRig(scene);
  EyeCamera left = rig.eye(Eye::Left), right = rig.eye(Eye::Right);
  const EmbreeIntersector& embree = backend.intersector();
  size_t visible = 0, roundTrips = 0;
  for (int y = 0; y < left.height; ++y)
    for (int x = 0; x < left.width; ++x) {
      // left pixel -> surface point -> right pixel -> right ray -> surface point -> left pixel
      Ray ray = left.generateRay(x + 0.5f, y + 0.5f);
      Hit hit;
      if (!embree.intersect(ray, INFINITY, hit)) continue;
      Vec3 p = ray.origin + ray.dir * hit.t;
      float rx, ry;
      if (!right.project(p, rx, ry) || !right.containsPixel(rx, ry)) continue;
      Ray back = right.generateRay(rx, ry);
      Hit hitBack;
      ASSERT_TRUE(embree.intersect(back, INFINITY, hitBack));
      if (hitBack.t < length(p - back.origin) * (1.0f - 1e-4f)) continue;  // hidden from the right eye
      ++visible;
      Vec3 q = back.origin + back.dir * hitBack.t;
      float lx, ly;
      ASSERT_TRUE(left.project(q, lx, ly));
      if (std::fabs(lx - (x + 0.5f)) < 1e-2f && std::fabs(ly - (y + 0.5f)) < 1e-2f) ++roundTrips;
    }
  EXPECT_GT(visible, size_t(left.width) * left.height / 2);
  EXPECT_GE(double(roundTrips), 0.999 * double(visible));
}

TEST(StereoReuse, ScatterNeverWritesAPointHiddenFromTheRightEye) {
  Scene scene = builtinScene("cornell");
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  const CpuBackend& backend = renderer.backendAs<CpuFrameBackend>().backend();
  StereoRig rig = smallRig(scene, 0.4f);  // a wide baseline hides much of what the left eye sees
  FrameResult frame = renderer.render(rig, stereoOptions(StereoMode::Scatter));
  EyeCamera left = rig.eye(Eye::Left), right = rig.eye(Eye::Right);
  const EmbreeIntersector& embree = backend.intersector();
  auto leftPoint = [&](uint32_t pixel, Vec3& p) {
    Ray ray = left.generateRay(pixel % left.width + 0.5f, pixel / left.width + 0.5f);
    Hit hit;
    if (!embree.intersect(ray, INFINITY, hit)) return false;
    p = ray.origin + ray.dir * hit.t;
    return true;
  };
  auto visibleFromRight = [&](Vec3 p) {
    Vec3 toEye = right.pose.position - p;
    float d = length(toEye);
    Ray r{p + toEye / d * (2.0f * scene.view().rayEpsilon()), toEye / d};
    return !embree.occluded(r, d * (1.0f - 1e-3f));
  };
  // Left points the right eye cannot see, though they project into its image: there must be many.
  size_t hidden = 0;
  for (uint32_t i = 0; i < uint32_t(left.width * left.height); ++i) {
    Vec3 p;
    float rx, ry;
    if (leftPoint(i, p) && right.project(p, rx, ry) && right.containsPixel(rx, ry) && !visibleFromRight(p)) ++hidden;
  }
  EXPECT_GT(hidden, 200u);
  const EyeResult& r = frame.eyes[1];
  size_t reused = 0;
  for (size_t i = 0; i < r.reusedFrom->size(); ++i) {
    if (r.reusedFrom.value()[i] == kNotReused) continue;
    ++reused;
    Vec3 p;
    ASSERT_TRUE(leftPoint(r.reusedFrom.value()[i], p));
    ASSERT_TRUE(visibleFromRight(p)) << "right pixel " << i << " took hidden left pixel " << r.reusedFrom.value()[i];
    float rx, ry;
    ASSERT_TRUE(right.project(p, rx, ry));
    EXPECT_EQ(size_t(ry) * right.width + size_t(rx), i) << "a left point lands on the pixel it projects to";
  }
  EXPECT_EQ(reused, frame.reusedPixels);
  EXPECT_GT(reused, r.reusedFrom->size() / 4);
}

TEST(StereoReuse, NothingSeenThroughMirrorsOrGlassIsReused) {
  Scene scene = builtinScene("cornell-caustics");
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  StereoRig rig = smallRig(scene);
  FrameResult separate = renderer.render(rig, stereoOptions(StereoMode::Separate));
  auto specular = [&](uint32_t prim) { return prim != ~0u && scene.materials()[scene.view().materialIds[prim]].isSpecular(); };
  for (StereoMode mode : {StereoMode::Gather, StereoMode::Scatter}) {
    SCOPED_TRACE(stereoModeName(mode));
    FrameResult frame = renderer.render(rig, stereoOptions(mode));
    const EyeResult& r = frame.eyes[1];
    size_t specularPixels = 0, scatteredOntoSpecular = 0;
    for (size_t i = 0; i < r.reusedFrom->size(); ++i) {
      specularPixels += specular(separate.eyes[1].firstPrim.value()[i]) ? 1 : 0;
      if (r.reusedFrom.value()[i] == kNotReused) continue;
      ASSERT_FALSE(specular(frame.eyes[0].firstPrim.value()[r.reusedFrom.value()[i]])) << "left pixel sees a mirror or glass";
      // Gather decides from the right pixel's own first hit. Scatter cannot know what a right
      // pixel's centre sees: a left point visible from the right eye may land on a pixel whose
      // centre just grazes a sphere's silhouette (the paper's scheme; counted below).
      if (mode == StereoMode::Gather) {
        ASSERT_FALSE(specular(separate.eyes[1].firstPrim.value()[i])) << "right pixel " << i << " sees a mirror or glass";
      } else {
        scatteredOntoSpecular += specular(separate.eyes[1].firstPrim.value()[i]) ? 1 : 0;
      }
    }
    EXPECT_GT(specularPixels, 300u);  // the spheres fill a good part of the view
    EXPECT_LE(scatteredOntoSpecular, specularPixels / 10);
    EXPECT_GT(countReused(r), r.reusedFrom->size() / 3);
    // Reflections and refractions are the right eye's own: exactly the separate rendering.
    expectShadedPixelsEqualSeparate(frame, separate);
  }
}

TEST(StereoReuse, ZeroIpdReusesEveryPixelAndGivesIdenticalImages) {
  Scene scene = builtinScene("cornell");
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  StereoRig rig = smallRig(scene, 0.0f);
  rig.fov[1] = rig.fov[0];
  for (StereoMode mode : {StereoMode::Gather, StereoMode::Scatter}) {
    SCOPED_TRACE(stereoModeName(mode));
    FrameResult frame = renderer.render(rig, stereoOptions(mode));
    const EyeResult &l = frame.eyes[0], &r = frame.eyes[1];
    size_t surfacePixels = 0, reusedInPlace = 0;
    for (size_t i = 0; i < l.firstPrim->size(); ++i) {
      if (l.firstPrim.value()[i] == ~0u) {  // the open front of the box: background, black in both eyes
        ASSERT_EQ(r.reusedFrom.value()[i], kNotReused);
        ASSERT_TRUE(isBlack(r.image.pixels[i]) && isBlack(l.image.pixels[i]));
        continue;
      }
      ++surfacePixels;
      if (r.reusedFrom.value()[i] != kNotReused) {
        ASSERT_EQ(r.reusedFrom.value()[i], uint32_t(i)) << "pixel " << i << " took another pixel's shading";
        ASSERT_TRUE(r.image.pixels[i].x == l.image.pixels[i].x && r.image.pixels[i].y == l.image.pixels[i].y &&
                    r.image.pixels[i].z == l.image.pixels[i].z);
        ++reusedInPlace;
      }
    }
    EXPECT_GT(surfacePixels, l.firstPrim->size() / 3);
    EXPECT_EQ(frame.reusedPixels, reusedInPlace);
    // Gather compares the very same hit: every surface pixel. Scatter's visibility ray back to the
    // eye may clip an edge it grazes, in float: a handful of pixels are then shaded again.
    if (mode == StereoMode::Gather) EXPECT_EQ(reusedInPlace, surfacePixels);
    else EXPECT_GE(double(reusedInPlace), 0.999 * double(surfacePixels));
  }
}

TEST(StereoReuse, HugeIpdReusesAlmostNothingAndEqualsSeparateRendering) {
  Scene scene = builtinScene("cornell");
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  // The right eye 1.5 m to the side sees the outside of the box's right wall, the left eye its
  // inside: same triangles, opposite sides, nothing to share.
  StereoRig rig = smallRig(scene, 3.0f);
  FrameResult separate = renderer.render(rig, stereoOptions(StereoMode::Separate));
  size_t rightSurface = 0;
  for (uint32_t p : *separate.eyes[1].firstPrim) rightSurface += p != ~0u ? 1 : 0;
  EXPECT_GT(rightSurface, separate.eyes[1].firstPrim->size() / 20) << "the right eye must see the box";
  for (StereoMode mode : {StereoMode::Gather, StereoMode::Scatter}) {
    SCOPED_TRACE(stereoModeName(mode));
    FrameResult frame = renderer.render(rig, stereoOptions(mode));
    EXPECT_LE(frame.reusedPixels, frame.eyes[1].reusedFrom->size() / 100);
    expectShadedPixelsEqualSeparate(frame, separate);
    ImageComparison c = compareDisplayed(frame.eyes[1].image, separate.eyes[1].image);
    EXPECT_GE(c.psnr, 40.0);
  }
}

TEST(StereoReuse, GatherIsInvisibleOnTheCornellBox) {
  // The paper's photon-map-only shading is deterministic given the map: the right eye rendered
  // with reuse differs from its separate rendering only by sub-pixel position.
  Scene scene = builtinScene("cornell");
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  StereoRig rig = smallRig(scene);
  FrameResult separate = renderer.render(rig, stereoOptions(StereoMode::Separate, ShadingMode::PhotonMapOnly));
  FrameResult gather = renderer.render(rig, stereoOptions(StereoMode::Gather, ShadingMode::PhotonMapOnly));
  FrameResult scatter = renderer.render(rig, stereoOptions(StereoMode::Scatter, ShadingMode::PhotonMapOnly));
  size_t surfacePixels = 0;
  for (uint32_t p : *separate.eyes[1].firstPrim) surfacePixels += p != ~0u ? 1 : 0;
  EXPECT_GT(double(gather.reusedPixels), 0.9 * double(surfacePixels));
  EXPECT_GT(double(scatter.reusedPixels), 0.8 * double(surfacePixels));
  expectShadedPixelsEqualSeparate(gather, separate);
  expectShadedPixelsEqualSeparate(scatter, separate);
  ImageComparison g = compareDisplayed(gather.eyes[1].image, separate.eyes[1].image);
  ImageComparison s = compareDisplayed(scatter.eyes[1].image, separate.eyes[1].image);
  EXPECT_GE(g.psnr, 40.0);
  // At this coarse resolution a sub-pixel shift moves the point by ~1 cm, against a 6 cm radius.
  EXPECT_LE(g.fractionOver1Percent, 0.3);
  std::printf("right eye with reuse vs separate, 144x160: gather %.1f dB (%.1f%% > 1%%), scatter %.1f dB (%.1f%%)\n",
              g.psnr, 100 * g.fractionOver1Percent, s.psnr, 100 * s.fractionOver1Percent);
  EXPECT_GE(g.psnr, s.psnr - 0.5) << "gather is at least as good as the paper's scatter";
  // The left eye is never affected by reuse.
  for (size_t i = 0; i < separate.eyes[0].image.pixels.size(); ++i)
    ASSERT_EQ(gather.eyes[0].image.pixels[i].x, separate.eyes[0].image.pixels[i].x);
}

// Foveated eyes reuse per mask vertex: a right vertex on a pixel centre (the whole full-density
// region) may take the shading of the left pixel that a left vertex recorded.
TEST(StereoReuse, FoveatedEyesReuseTheLeftVerticesShading) {
  Scene scene = builtinScene("cornell");
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  StereoRig rig = smallRig(scene);
  MaskParams params = maskParamsForRig(rig);
  params.tanPerPixel *= 9.0f;  // a coarse pixel: the headset's falloff on a small image
  params.acuity.gazeMarginDeg = 3.0f;
  FoveationMask mask = generateFoveationMask(params);
  for (StereoMode mode : {StereoMode::Gather, StereoMode::Scatter}) {
    SCOPED_TRACE(stereoModeName(mode));
    RenderOptions o = stereoOptions(mode, ShadingMode::PhotonMapOnly);
    o.foveation.mask = &mask;
    RenderOptions separateOptions = o;
    separateOptions.stereo = StereoMode::Separate;
    FrameResult reused = renderer.render(rig, o), separate = renderer.render(rig, separateOptions);
    // The candidates: right vertices on pixel centres that see a surface (all diffuse here).
    auto candidatesOf = [&](const FrameResult& frame) {
      FoveationOptions f;
      std::copy(frame.gaze[1], frame.gaze[1] + 2, f.gaze[1]);
      int gx, gy;
      f.gazePixel(1, rig.width, rig.height, gx, gy);
      std::vector<uint8_t> inUse = verticesInUse(mask, gx, gy);
      size_t n = 0;
      for (size_t v = 0; v < inUse.size(); ++v) {
        float px = mask.offsets[v].x + float(gx), py = mask.offsets[v].y + float(gy);
        if (inUse[v] && px == std::floor(px) && py == std::floor(py) && px >= 0 && py >= 0 && px < rig.width &&
            py < rig.height)
          n += frame.eyes[1].inverseDepth[size_t(py) * rig.width + size_t(px)] > 0.0f ? 1 : 0;
      }
      return n;
    };
    const size_t candidates = candidatesOf(reused);
    ASSERT_GT(candidates, 200u);
    // Only where the two full-density regions overlap on the scene: on this coarse mask they are
    // ~8 pixels wide, and the same gaze fraction in both eyes points ~4 deg apart (asymmetric
    // FOVs) before parallax.
    EXPECT_GT(double(reused.reusedPixels), 0.25 * double(candidates));
    EXPECT_LE(reused.reusedPixels, candidates);
    EXPECT_EQ(reused.shadedSamples[1], separate.shadedSamples[1]);
    EXPECT_TRUE(!reused.eyes[1].reusedFrom.has_value()) << "foveated reuse is per vertex";
    EXPECT_GE(compareDisplayed(reused.eyes[1].image, separate.eyes[1].image).psnr, 40.0);
    EXPECT_EQ(compareDisplayed(reused.eyes[0].image, separate.eyes[0].image).meanSquaredError, 0.0) << "the left eye is unaffected";
    // Eyes that fixate one point (vergence) share most of their full-density regions.
    o.foveation.verge = true;
    FrameResult verged = renderer.render(rig, o);
    EXPECT_GT(double(verged.reusedPixels), 0.8 * double(candidatesOf(verged)));
    EXPECT_GT(verged.reusedPixels, 2 * reused.reusedPixels);
    o.foveation.verge = false;
    // IPD 0 with equal FOVs and gazes: every vertex the right eye takes is the left one's own
    // value at the same position, so the right image is the left image.
    StereoRig same = smallRig(scene, 0.0f);
    same.fov[1] = same.fov[0];
    FrameResult one = renderer.render(same, o);
    EXPECT_GE(double(one.reusedPixels), 0.99 * double(candidates));
    EXPECT_EQ(compareDisplayed(one.eyes[1].image, one.eyes[0].image).meanSquaredError, 0.0);
  }
}

TEST(StereoReuse, ReuseNeedsBothEyes) {
  Scene scene = builtinScene("cornell");
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  RenderOptions o = stereoOptions(StereoMode::Gather);
  o.eyes[0] = false;
  EXPECT_THROW(renderer.render(smallRig(scene), o), Error);
  EXPECT_THROW(parseStereoMode("both"), Error);
  EXPECT_EQ(parseStereoMode("scatter"), StereoMode::Scatter);
}

TEST(ImageCompare, PsnrOfAKnownDifference) {
  Image a(4, 4), b(4, 4);
  for (auto& p : a.pixels) p = Vec3(1.0f);  // white: display value 1
  b = a;
  EXPECT_TRUE(std::isinf(compareDisplayed(a, b).psnr));
  b.pixels[0] = Vec3(0.0f);  // one pixel black: MSE = 3 / (3 * 16)
  ImageComparison c = compareDisplayed(b, a);
  EXPECT_NEAR(c.psnr, 10.0 * std::log10(16.0), 1e-5);
  EXPECT_DOUBLE_EQ(c.fractionOver1Percent, 1.0 / 16.0);
  std::vector<uint8_t> mask(16, 1);
  mask[0] = 0;
  EXPECT_TRUE(std::isinf(compareDisplayed(b, a, mask).psnr));
  EXPECT_THROW(compareDisplayed(Image(2, 2), a), Error);
}

}  // namespace
}  // namespace pvr
