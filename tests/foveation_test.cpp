// Foveation masks: the acuity model's spacing, the mask's coverage of the image wherever the gaze
// is, the Delaunay property of its triangulation and its coverage of the convex hull, exact
// reconstruction of constant and linear colour fields, and the mask file's round trip and
// rejection of bad files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "pvr/foveation/mask.h"
#include "pvr/cpu/cpu_frame_backend.h"
#include "pvr/render/renderer.h"
#include "pvr/util/error.h"

namespace pvr {
namespace {

// A small eye with a coarse pixel (9x the headset's angle per pixel): the same falloff on a mask
// of a few thousand vertices.
MaskParams smallParams(AcuityKind kind = AcuityKind::LinearMar) {
  MaskParams p;
  p.width = 160;
  p.height = 176;
  p.tanPerPixel = 9.0f * 0.00185f;
  p.acuity.kind = kind;
  p.acuity.gazeMarginDeg = 3.0f;
  return p;
}

TEST(Acuity, SpacingGrowsWithEccentricityAndIsThePixelPitchAtTheFovea) {
  for (AcuityKind kind : {AcuityKind::LinearMar, AcuityKind::GeislerPerry}) {
    AcuityModel model;
    model.kind = kind;
    const float pitch = 0.1f;  // degrees, a headset's pixel
    EXPECT_FLOAT_EQ(model.sampleSpacingDeg(0.0f, pitch), pitch) << "the display limits the fovea";
    EXPECT_FLOAT_EQ(model.sampleSpacingDeg(model.gazeMarginDeg, pitch), pitch) << "full density inside the margin";
    float previous = 0;
    for (float e = 0; e <= 90.0f; e += 0.25f) {
      float s = model.acuitySpacingDeg(e);
      ASSERT_GE(s, previous) << "e = " << e;
      previous = s;
    }
    EXPECT_GT(model.acuitySpacingDeg(60.0f), 3.0f * pitch) << "the periphery is coarse";
  }
  AcuityModel linear;
  EXPECT_NEAR(linear.acuitySpacingDeg(linear.gazeMarginDeg + 10.0f), 1.0f / 48.0f + 0.22f, 1e-6f);
  AcuityModel gp;
  gp.kind = AcuityKind::GeislerPerry;
  // f_c(0) = ln(64) / 0.106 = 39.2 cycles/deg: a sample every 1/78 deg at the fovea.
  EXPECT_NEAR(gp.acuitySpacingDeg(0.0f), 0.5f * 0.106f / std::log(64.0f), 1e-6f);
  MaskParams p = smallParams();
  EXPECT_DOUBLE_EQ(sampleSpacingPixels(p, 0.0), 1.0);
  double previous = 1.0;
  for (double r = 0; r < 400; r += 0.5) {
    double s = sampleSpacingPixels(p, r);
    ASSERT_GE(s, previous - 1e-9) << "r = " << r;
    previous = s;
  }
}

TEST(FoveationMask, CoversTheImageForGazeAtTheCornersAndCentre) {
  FoveationMask mask = generateFoveationMask(smallParams());
  const int w = mask.params.width, h = mask.params.height;
  EXPECT_GT(mask.fullDensityRadius, 0);
  std::vector<Vec3> ones(mask.offsets.size(), Vec3(1.0f));
  for (auto [gx, gy] : {std::pair{0, 0}, {w - 1, 0}, {0, h - 1}, {w - 1, h - 1}, {w / 2, h / 2}}) {
    Image image = reconstructFoveatedImage(mask, gx, gy, ones);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        ASSERT_NEAR(image.at(x, y).x, 1.0f, 1e-6f) << "gaze " << gx << "," << gy << ": pixel " << x << "," << y;
  }
}

// Twice the signed area of the convex hull (Andrew's monotone chain).
double hullArea(std::vector<MaskPoint> p) {
  std::sort(p.begin(), p.end(), [](MaskPoint a, MaskPoint b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  auto cross = [](MaskPoint o, MaskPoint a, MaskPoint b) {
    return (double(a.x) - o.x) * (double(b.y) - o.y) - (double(a.y) - o.y) * (double(b.x) - o.x);
  };
  std::vector<MaskPoint> hull(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p[i]) <= 0) --k;
    hull[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], p[i - 1]) <= 0) --k;
    hull[k++] = p[i - 1];
  }
  double area = 0;
  for (size_t i = 0; i + 1 < k; ++i) area += double(hull[i].x) * hull[i + 1].y - double(hull[i + 1].x) * hull[i].y;
  return area;
}

TEST(FoveationMask, TriangulationIsDelaunayAndCoversTheConvexHull) {
  FoveationMask mask = generateFoveationMask(smallParams());
  ASSERT_GT(mask.offsets.size(), 1000u);
  ASSERT_LT(mask.offsets.size(), 20000u);
  std::vector<uint8_t> used(mask.offsets.size(), 0);
  double area = 0;
  size_t violations = 0;
  for (size_t t = 0; t < mask.triangleCount(); ++t) {
    const MaskPoint& a = mask.offsets[mask.triangles[3 * t]];
    const MaskPoint& b = mask.offsets[mask.triangles[3 * t + 1]];
    const MaskPoint& c = mask.offsets[mask.triangles[3 * t + 2]];
    for (int k = 0; k < 3; ++k) used[mask.triangles[3 * t + k]] = 1;
    double orient = orient2d(a, b, c.x, c.y);
    ASSERT_GT(std::fabs(orient), 0.0) << "degenerate triangle " << t;
    area += std::fabs(orient);
    // Empty circumcircle: no vertex strictly inside (co-circular grid points are allowed).
    double ax = a.x, ay = a.y, bx = b.x, by = b.y, cx = c.x, cy = c.y;
    double d = 2 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by));
    double ux = ((ax * ax + ay * ay) * (by - cy) + (bx * bx + by * by) * (cy - ay) + (cx * cx + cy * cy) * (ay - by)) / d;
    double uy = ((ax * ax + ay * ay) * (cx - bx) + (bx * bx + by * by) * (ax - cx) + (cx * cx + cy * cy) * (bx - ax)) / d;
    double r2 = (ax - ux) * (ax - ux) + (ay - uy) * (ay - uy);
    for (const MaskPoint& p : mask.offsets) {
      double d2 = (p.x - ux) * (p.x - ux) + (p.y - uy) * (p.y - uy);
      if (d2 < r2 * (1.0 - 1e-6) - 1e-6) ++violations;
    }
  }
  EXPECT_EQ(violations, 0u);
  EXPECT_NEAR(area, hullArea(mask.offsets), 1e-6 * area) << "the triangles tile the convex hull";
  EXPECT_EQ(std::count(used.begin(), used.end(), 1), std::ptrdiff_t(mask.offsets.size())) << "every sample is a vertex";
}

TEST(FoveationMask, ReconstructsConstantAndLinearColourFieldsExactly) {
  FoveationMask mask = generateFoveationMask(smallParams());
  const int w = mask.params.width, h = mask.params.height;
  for (auto [gx, gy] : {std::pair{w / 2, h / 2}, {17, h - 5}}) {
    auto field = [&](double x, double y) {  // image-space position
      return Vec3(float(0.25 + 0.01 * x), float(2.0 - 0.005 * y), float(0.003 * x + 0.002 * y));
    };
    std::vector<Vec3> colours(mask.offsets.size());
    for (size_t i = 0; i < colours.size(); ++i)
      colours[i] = field(mask.offsets[i].x + gx + 0.5, mask.offsets[i].y + gy + 0.5);
    Image image = reconstructFoveatedImage(mask, gx, gy, colours);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        Vec3 expected = field(x + 0.5, y + 0.5), got = image.at(x, y);
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(got[c], expected[c], 2e-5f * (1.0f + std::fabs(expected[c])));
      }
  }
  // Inside the full-density disc every pixel centre is a vertex: the image there is the samples.
  std::vector<Vec3> random(mask.offsets.size());
  for (size_t i = 0; i < random.size(); ++i) random[i] = Vec3(float((i * 7919) % 1000) / 1000.0f);
  Image image = reconstructFoveatedImage(mask, w / 2, h / 2, random);
  for (size_t i = 0; i < mask.offsets.size(); ++i) {
    const MaskPoint& o = mask.offsets[i];
    if (o.x * o.x + o.y * o.y > float(mask.fullDensityRadius * mask.fullDensityRadius)) continue;
    ASSERT_EQ(image.at(w / 2 + int(o.x), h / 2 + int(o.y)).x, random[i].x);
  }
}

// The GPU raster sorts triangles by triangleBoxSize at a central gaze once (a load-balancing hint:
// each triangle still computes its own bounds). Inside the image it is triangleBounds' box, and
// at any other gaze that box is at most a pixel wider or taller (float rounding).
TEST(FoveationMask, TriangleBoxSizeBarelyDependsOnTheGaze) {
  FoveationMask mask = generateFoveationMask(smallParams());
  const int w = mask.params.width, h = mask.params.height;
  size_t compared = 0, small = 0, same = 0;
  for (size_t t = 0; t < mask.triangleCount(); ++t) {
    int bw, bh;
    triangleBoxSize(mask.offsets.data(), mask.triangles.data(), t, w / 2, h / 2, bw, bh);
    small += bw * bh <= 8 ? 1 : 0;
    for (auto [gx, gy] : {std::pair{w / 2, h / 2}, std::pair{w / 3, 2 * h / 3}, std::pair{w - 7, 5}}) {
      MaskPoint v[3];
      uint32_t index[3];
      placeTriangle(mask.offsets.data(), mask.triangles.data(), t, gx, gy, v, index);
      bool inside = true;
      for (const MaskPoint& p : v) inside = inside && p.x > 2 && p.y > 2 && p.x < w - 2 && p.y < h - 2;
      if (!inside) continue;
      int x0, x1, y0, y1;
      ASSERT_TRUE(triangleBounds(v, w, h, x0, x1, y0, y1));
      if (gx == w / 2 && gy == h / 2) {
        ASSERT_EQ(x1 - x0, bw) << "triangle " << t;
        ASSERT_EQ(y1 - y0, bh) << "triangle " << t;
      }
      ASSERT_LE(std::abs(x1 - x0 - bw), 1) << "triangle " << t << " gaze " << gx << "," << gy;
      ASSERT_LE(std::abs(y1 - y0 - bh), 1) << "triangle " << t << " gaze " << gx << "," << gy;
      same += x1 - x0 == bw && y1 - y0 == bh ? 1 : 0;
      ++compared;
    }
  }
  EXPECT_GT(compared, mask.triangleCount() / 4);
  EXPECT_GT(same, compared / 2);
  EXPECT_GT(small, mask.triangleCount() / 4) << "the fovea's triangles are small";
}

TEST(FoveationMask, DefaultHeadsetMaskShadesAtLeastFourTimesFewerSamples) {
  for (AcuityKind kind : {AcuityKind::LinearMar, AcuityKind::GeislerPerry}) {
    MaskParams p;  // 1440x1600
    p.tanPerPixel = 0.00185f;
    p.acuity.kind = kind;
    FoveationMask mask = generateFoveationMask(p);
    std::vector<uint8_t> used = verticesInUse(mask, p.width / 2, p.height / 2);
    double shaded = double(std::count(used.begin(), used.end(), 1));
    EXPECT_LT(4.0 * shaded, double(p.width) * p.height) << int(kind);
    EXPECT_GE(eccentricityDeg(mask.fullDensityRadius, p.tanPerPixel), p.acuity.gazeMarginDeg);
  }
}

TEST(FoveationMask, FileRoundTripAndBadFiles) {
  FoveationMask mask = generateFoveationMask(smallParams(AcuityKind::GeislerPerry));
  std::filesystem::path dir = std::filesystem::temp_directory_path() / "pvr_mask_test";
  std::filesystem::create_directories(dir);
  std::string path = (dir / "mask.pvrmask").string();
  saveFoveationMask(mask, path);
  FoveationMask back = loadFoveationMask(path);
  EXPECT_EQ(back.params.width, mask.params.width);
  EXPECT_EQ(back.params.acuity.kind, AcuityKind::GeislerPerry);
  EXPECT_EQ(back.fullDensityRadius, mask.fullDensityRadius);
  EXPECT_EQ(back.triangles, mask.triangles);
  ASSERT_EQ(back.offsets.size(), mask.offsets.size());
  for (size_t i = 0; i < mask.offsets.size(); ++i) ASSERT_EQ(back.offsets[i].x, mask.offsets[i].x);
  // Every mask made or loaded has its own id (what the GPU keys its uploaded copy on); copies share it.
  EXPECT_NE(back.id, 0u);
  EXPECT_NE(back.id, mask.id);
  FoveationMask copy = back;
  EXPECT_EQ(copy.id, back.id);

  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto writeFile = [&](const std::string& name, const std::string& content) {
    std::string p = (dir / name).string();
    std::ofstream(p, std::ios::binary) << content;
    return p;
  };
  EXPECT_THROW(loadFoveationMask((dir / "missing.pvrmask").string()), Error);
  EXPECT_THROW(loadFoveationMask(writeFile("truncated.pvrmask", bytes.substr(0, bytes.size() - 5))), Error);
  EXPECT_THROW(loadFoveationMask(writeFile("magic.pvrmask", "PVRMESH1" + bytes.substr(8))), Error);
  EXPECT_THROW(loadFoveationMask(writeFile("trailing.pvrmask", bytes + "x")), Error);
  std::string badIndex = bytes;
  uint32_t huge = 0xfffffff0u;
  std::memcpy(&badIndex[badIndex.size() - 4], &huge, 4);
  EXPECT_THROW(loadFoveationMask(writeFile("index.pvrmask", badIndex)), Error);
  // A header claiming the most vertices in a small file is refused from the file's size, before
  // half a gigabyte is allocated (found by the fuzzer: it took over a second under ASan).
  std::string hugeCount = bytes;
  const uint32_t mostVertices = 1u << 26;
  constexpr size_t kVertexCountOffset = 56;  // magic, version, size, tan/pixel, acuity (7 fields), radius
  uint32_t stored;
  std::memcpy(&stored, &hugeCount[kVertexCountOffset], 4);
  ASSERT_EQ(stored, mask.offsets.size());
  std::memcpy(&hugeCount[kVertexCountOffset], &mostVertices, 4);
  try {
    loadFoveationMask(writeFile("count.pvrmask", hugeCount));
    ADD_FAILURE() << "a vertex count beyond the file's size was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("claims 67108864 vertices"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(FoveationMask, RejectsBadParameters) {
  MaskParams p = smallParams();
  p.tanPerPixel = 0;
  EXPECT_THROW(generateFoveationMask(p), Error);
  p = smallParams();
  p.acuity.marSlope = -1;
  EXPECT_THROW(generateFoveationMask(p), Error);
  p = smallParams();
  p.width = 0;
  EXPECT_THROW(generateFoveationMask(p), Error);
}

TEST(FoveatedRender, TheFoveaIsTheFullResolutionImageAndFewerSamplesAreShaded) {
  Scene scene = builtinScene("cornell");
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  StereoRig rig = scene.rig;
  rig.width = 160, rig.height = 176;
  MaskParams params = maskParamsForRig(rig);
  params.acuity = smallParams().acuity;
  FoveationMask mask = generateFoveationMask(params);
  RenderOptions o;
  o.photonsX = o.photonsY = 96;
  o.gather.density.radius = 0.06f;
  FrameResult full = renderer.render(rig, o);
  o.foveation.mask = &mask;
  o.foveation.gaze[0][0] = 0.4f, o.foveation.gaze[0][1] = 0.55f;
  FrameResult foveated = renderer.render(rig, o);
  for (int e = 0; e < 2; ++e) {
    int gx, gy;
    o.foveation.gazePixel(e, rig.width, rig.height, gx, gy);
    size_t inside = 0;
    for (int y = 0; y < rig.height; ++y)
      for (int x = 0; x < rig.width; ++x) {
        if ((x - gx) * (x - gx) + (y - gy) * (y - gy) > mask.fullDensityRadius * mask.fullDensityRadius) continue;
        ++inside;
        const Vec3 &a = foveated.eyes[e].image.at(x, y), &b = full.eyes[e].image.at(x, y);
        ASSERT_TRUE(a.x == b.x && a.y == b.y && a.z == b.z) << "eye " << e << " pixel " << x << "," << y;
      }
    EXPECT_GT(inside, 500u);
    EXPECT_LT(foveated.shadedSamples[e], full.shadedSamples[e]);
    EXPECT_EQ(full.shadedSamples[e], size_t(rig.width) * rig.height);
  }
  // A mask for another eye size is refused.
  rig.width = 150;
  EXPECT_THROW(renderer.render(rig, o), Error);
}

// With one gaze for both eyes, the right eye looks at the surface point the left eye fixates.
TEST(FoveatedRender, VergedEyesFixateTheSamePoint) {
  Scene scene = builtinScene("cornell");
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  const CpuBackend& backend = renderer.backendAs<CpuFrameBackend>().backend();
  StereoRig rig = scene.rig;
  rig.width = 160, rig.height = 176;
  rig.ipd = 0.2f;  // a wide baseline: a large disparity
  MaskParams params = maskParamsForRig(rig);
  params.acuity = smallParams().acuity;
  FoveationMask mask = generateFoveationMask(params);
  RenderOptions o;
  o.photonsX = o.photonsY = 32;
  o.foveation.mask = &mask;
  o.foveation.verge = true;
  for (float gx : {0.3f, 0.5f, 0.62f}) {
    o.foveation.gaze[0][0] = gx, o.foveation.gaze[0][1] = 0.55f;
    FrameResult frame = renderer.render(rig, o);
    EXPECT_EQ(frame.gaze[0][0], gx);
    Vec3 fixated[2];
    for (int e = 0; e < 2; ++e) {
      FoveationOptions f;
      std::copy(frame.gaze[e], frame.gaze[e] + 2, f.gaze[e]);
      int x, y;
      f.gazePixel(e, rig.width, rig.height, x, y);
      Ray ray = rig.eye(Eye(e)).generateRay(x + 0.5f, y + 0.5f);
      Hit hit;
      ASSERT_TRUE(backend.intersector().intersect(ray, INFINITY, hit));
      fixated[e] = ray.origin + ray.dir * hit.t;
    }
    // Within two pixels' width on the surface (the right gaze is rounded to a pixel).
    float pixel = length(fixated[0] - rig.eye(Eye::Left).pose.position) * params.tanPerPixel;
    EXPECT_LT(length(fixated[0] - fixated[1]), 2.0f * pixel) << "gaze x " << gx;
    EXPECT_GT(std::fabs(frame.gaze[1][0] - gx), 0.02f) << "the disparity moves the right eye's gaze";
  }
}

}  // namespace
}  // namespace pvr
