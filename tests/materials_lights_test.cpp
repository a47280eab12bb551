// Textures, alpha cut-outs and lights without area, against exact expectations: texel lookups,
// wrap modes and the mip chain; the ray cone's level of detail on a plane; a cut-out quad's shadow
// on both intersectors (Embree's filter and the GPU BVH's any-hit, run on the host); a point
// light's inverse-square cosine irradiance (direct exactly, the photon map within its noise); a
// spot's cone edges; a distant light's E cos; the photons carry the lights' power.
#include <gtest/gtest.h>

#include <cmath>

#include "pvr/accel/bvh_traversal.h"
#include "pvr/cpu/cpu_backend.h"
#include "pvr/photon/deferred_shadows.h"
#include "pvr/photon/gather.h"
#include "pvr/photon/hash_grid.h"
#include "pvr/scene/scene.h"
#include "pvr/util/error.h"
#include "test_scenes.h"

namespace pvr {
namespace {

uint32_t rgba(uint8_t r, uint8_t g, uint8_t b, uint8_t a = 255) { return r | g << 8 | b << 16 | uint32_t(a) << 24; }

// A 4x4 texture whose texel (x, y) has R = 16 x + 1, G = 16 y + 2, B = 200, A = 60 x.
Scene checkerScene(WrapMode s, WrapMode t) {
  Scene scene;
  std::vector<uint32_t> texels;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) texels.push_back(rgba(uint8_t(16 * x + 1), uint8_t(16 * y + 2), 200, uint8_t(60 * x)));
  scene.addTexture("checker", 4, 4, texels, false, s, t);
  return scene;
}

TEST(Textures, TexelCentresReturnTheTexelExactly) {
  Scene scene = checkerScene(WrapMode::Repeat, WrapMode::Repeat);
  const TextureView& t = scene.textureViews()[0];
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      Rgba c = sampleTexture(t, {(x + 0.5f) / 4.0f, (y + 0.5f) / 4.0f}, 0.0f);
      EXPECT_FLOAT_EQ(c.rgb.x, (16 * x + 1) / 255.0f);
      EXPECT_FLOAT_EQ(c.rgb.y, (16 * y + 2) / 255.0f);
      EXPECT_FLOAT_EQ(c.rgb.z, 200 / 255.0f);
      EXPECT_FLOAT_EQ(c.a, (60 * x) / 255.0f);
    }
}

TEST(Textures, WrapModes) {
  auto red = [](const Scene& s, float u) { return sampleTexture(s.textureViews()[0], {u, 0.125f}, 0.0f).rgb.x * 255.0f; };
  Scene repeat = checkerScene(WrapMode::Repeat, WrapMode::Repeat);
  Scene clamp = checkerScene(WrapMode::ClampToEdge, WrapMode::ClampToEdge);
  Scene mirror = checkerScene(WrapMode::MirroredRepeat, WrapMode::MirroredRepeat);
  EXPECT_FLOAT_EQ(red(repeat, 1.125f), 1.0f);      // texel 0 again
  EXPECT_FLOAT_EQ(red(repeat, -0.625f), 17.0f);    // 0.375: texel 1
  EXPECT_FLOAT_EQ(red(clamp, -3.0f), 1.0f);        // the edge texel
  EXPECT_FLOAT_EQ(red(clamp, 7.5f), 49.0f);
  EXPECT_FLOAT_EQ(red(mirror, 1.125f), 49.0f);     // mirrored: texel 3
  EXPECT_FLOAT_EQ(red(mirror, 1.875f), 1.0f);      // texel 0
  EXPECT_FLOAT_EQ(red(mirror, -0.125f), 1.0f);
  EXPECT_EQ(wrapTexel(-1, 4, WrapMode::MirroredRepeat), 0);  // 0 1 2 3 | 3 2 1 0 | 0 1 ...
  EXPECT_EQ(wrapTexel(5, 4, WrapMode::MirroredRepeat), 2);
  EXPECT_EQ(wrapTexel(9, 4, WrapMode::MirroredRepeat), 1);
}

TEST(Textures, MipChainAveragesInLinearLight) {
  Scene scene;
  // 2x2 black and white sRGB texels: the next level is their average in linear light, 0.5,
  // which sRGB encodes as 188.
  scene.addTexture("bw", 2, 2, {rgba(0, 0, 0), rgba(255, 255, 255), rgba(255, 255, 255), rgba(0, 0, 0)}, true);
  const TextureView& t = scene.textureViews()[0];
  ASSERT_EQ(t.levels, 2);
  EXPECT_EQ(t.texels[t.levelOffset[1]] & 255u, 188u);
  EXPECT_NEAR(sampleTexture(t, {0.3f, 0.7f}, 1.0f).rgb.x, 0.5f, 0.003f);
  // Half-way between the levels: the blend of both.
  float l0 = sampleTexture(t, {0.25f, 0.25f}, 0.0f).rgb.x, l1 = sampleTexture(t, {0.25f, 0.25f}, 1.0f).rgb.x;
  EXPECT_FLOAT_EQ(sampleTexture(t, {0.25f, 0.25f}, 0.5f).rgb.x, 0.5f * (l0 + l1));
  EXPECT_THROW(scene.addTexture("bad", 3, 3, {rgba(0, 0, 0)}, true), Error);
}

TEST(Textures, TransformFollowsGltf) {
  TextureRef ref;
  ref.offset = {0.5f, 0.25f};
  ref.scale = {2.0f, 3.0f};
  ref.rotation = 0.5f * kPi;  // glTF: u' = cos*su + sin*sv + tx, v' = -sin*su + cos*sv + ty
  Vec2 uv = ref.transform({0.1f, 0.2f});
  EXPECT_NEAR(uv.x, 0.6f + 0.5f, 1e-6f);
  EXPECT_NEAR(uv.y, -0.2f + 0.25f, 1e-6f);
}

// A unit quad on z = 0 facing +Z with UVs 0..1 and a 256x256 texture.
Scene texturedPlane(int size) {
  Scene scene;
  std::vector<uint32_t> texels(size_t(size) * size, rgba(128, 128, 128));
  Material m;
  m.baseColorTexture.texture = int32_t(scene.addTexture("grey", size, size, texels, true));
  uint32_t id = scene.addMaterial(m, "plane");
  std::vector<Vec2> uvs[2] = {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {}};
  scene.addMesh("plane", {{-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {0.5f, 0.5f, 0}, {-0.5f, 0.5f, 0}}, {}, uvs, {0, 1, 2, 0, 2, 3}, id);
  PunctualLight sun;
  sun.kind = PunctualKind::Directional;
  sun.direction = {0, 0, -1};
  scene.addPunctualLight(sun, "sun");
  scene.finalize();
  return scene;
}

TEST(Textures, RayConeChoosesTheExpectedLevel) {
  Scene scene = texturedPlane(256);
  SceneView v = scene.view();
  const TextureRef& ref = scene.materials()[0].baseColorTexture;
  // A cone as wide as one texel (1/256 m) seen head on is level 0; each doubling one level up;
  // a 60 degree slant widens it by 1 / cos.
  EXPECT_NEAR(v.textureLod(ref, 0, 1.0f / 256.0f, 1.0f), 0.0f, 1e-4f);
  EXPECT_NEAR(v.textureLod(ref, 0, 4.0f / 256.0f, 1.0f), 2.0f, 1e-4f);
  EXPECT_NEAR(v.textureLod(ref, 0, 1.0f / 256.0f, 0.5f), 1.0f, 1e-4f);
  // Through a camera: a pixel's footprint at distance d is d * pixelSpread.
  EyeCamera cam;
  cam.width = cam.height = 512;
  cam.fov = {-0.5f, 0.5f, 0.5f, -0.5f};
  float d = 2.0f, expected = 8.0f + std::log2(d * cam.pixelSpread());
  EXPECT_NEAR(v.textureLod(ref, 1, d * cam.pixelSpread(), 1.0f), expected, 1e-4f);
}

// A floor at y = 0, a quad at y = 0.5 whose texture's left half (u < 0.5) is cut out, and a
// shadow ray from each floor point straight up: blocked exactly where the quad is opaque.
TEST(Alpha, CutOutTexelsCastNoShadowOnBothIntersectors) {
  Scene scene = test::cutOutQuadOverFloor();
  ASSERT_TRUE(scene.hasAlphaTestedMaterial());
  EmbreeIntersector embree(scene);
  Bvh bvh = Bvh::build(scene);
  BvhIntersector ours{bvh.view()};
  const SceneView view = scene.view();
  ours.alphaScene = &view;
  int blocked = 0;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) {
      float x = -0.6f + 1.2f * (i + 0.5f) / 40.0f, z = -0.6f + 1.2f * (j + 0.5f) / 40.0f;
      Ray up{{x, 1e-3f, z}, {0, 1, 0}};
      bool expected = x > 0.0f && x < 0.5f && z > -0.5f && z < 0.5f;  // over the opaque half
      EXPECT_EQ(embree.occluded(up, 2.0f), expected) << x << " " << z;
      EXPECT_EQ(ours.occluded(up, 2.0f), expected) << x << " " << z;
      Hit a, b;
      embree.intersect(up, 2.0f, a);
      ours.intersect(up, 2.0f, b);
      EXPECT_EQ(a.valid(), expected);
      EXPECT_EQ(b.valid(), expected);
      blocked += expected;
    }
  EXPECT_GT(blocked, 100);
}

// A white diffuse floor (albedo 1) under one light; the radiance towards the eye at floor point
// p is (1 / pi) E(p), E the irradiance. Direct light is exact: every punctual light is evaluated.
struct LitFloor {
  Scene scene;
  explicit LitFloor(const PunctualLight& light) {
    Material white;
    white.albedo = {1, 1, 1};
    uint32_t id = scene.addMaterial(white, "floor");
    scene.addMesh("floor", {{-4, 0, -4}, {4, 0, -4}, {4, 0, 4}, {-4, 0, 4}}, {}, {0, 2, 1, 0, 3, 2}, id);
    scene.addPunctualLight(light, "light");
    scene.finalize();
  }
  Vec3 directRadiance(const EmbreeIntersector& intersector, Vec3 p) const {
    GatherParams params;
    Ray down{p + Vec3(0, 1.0f, 0.3f), normalize(Vec3(0, -1.0f, -0.3f))};
    CounterRng rng(1, 0, 0);
    return traceToGatherPoint(scene.view(), intersector, params, down, rng).radiance;
  }
};

TEST(Lights, PointLightIsInverseSquareTimesCosine) {
  PunctualLight lamp;
  lamp.position = {0.3f, 2.0f, -0.2f};
  lamp.intensity = {10, 5, 2};
  LitFloor floor(lamp);
  EmbreeIntersector intersector(floor.scene);
  for (Vec3 p : {Vec3(0.3f, 0, -0.2f), Vec3(1.5f, 0, 0.5f), Vec3(-2.0f, 0, 1.0f)}) {
    Vec3 toLight = lamp.position - p;
    float r2 = lengthSquared(toLight), cosTheta = toLight.y / std::sqrt(r2);
    Vec3 L = floor.directRadiance(intersector, p);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(L[c], lamp.intensity[c] * cosTheta / r2 / kPi, 1e-4f * L[c] + 1e-7f);
  }
}

TEST(Lights, SpotConeEdges) {
  PunctualLight spot;
  spot.kind = PunctualKind::Spot;
  spot.position = {0, 2, 0};
  spot.direction = {0, -1, 0};
  spot.intensity = {8, 8, 8};
  spot.cosInner = std::cos(0.3f), spot.cosOuter = std::cos(0.5f);
  LitFloor floor(spot);
  EmbreeIntersector intersector(floor.scene);
  auto at = [&](float angle) { return floor.directRadiance(intersector, {2.0f * std::tan(angle), 0, 0}).x; };
  auto full = [&](float angle) {  // inside the inner cone: I cos / r^2 / pi
    float r = 2.0f / std::cos(angle);
    return 8.0f * std::cos(angle) / (r * r) / kPi;
  };
  EXPECT_NEAR(at(0.0f), full(0.0f), 1e-4f);
  EXPECT_NEAR(at(0.29f), full(0.29f), 1e-4f);
  EXPECT_EQ(at(0.51f), 0.0f);
  float mid = at(0.4f);  // between the cones: glTF's smooth falloff, strictly between
  EXPECT_GT(mid, 0.0f);
  EXPECT_LT(mid, full(0.4f));
}

TEST(Lights, DistantLightIsIrradianceTimesCosine) {
  PunctualLight sun;
  sun.kind = PunctualKind::Directional;
  sun.direction = normalize(Vec3(0.6f, -0.8f, 0.0f));  // cos = 0.8 on the floor
  sun.intensity = {5, 4, 3};
  LitFloor floor(sun);
  EmbreeIntersector intersector(floor.scene);
  Vec3 L = floor.directRadiance(intersector, {0.5f, 0, 0.5f});
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(L[c], sun.intensity[c] * 0.8f / kPi, 1e-5f);
}

// Several punctual lights with one shadow ray chosen among them by unoccluded contribution: where
// every light is visible the estimate's luminance is the exact sum's for every random number (no
// selection noise but the lights' colours); the mean over many paths is the exact sum, per
// channel, where every light is visible and where a blocker hides one (unbiased).
TEST(Lights, OneShadowRayAmongManyLightsIsExactWhenVisibleAndUnbiasedWhenNot) {
  Scene scene;
  Material white;
  white.albedo = {1, 1, 1};
  uint32_t id = scene.addMaterial(white, "floor");
  scene.addMesh("floor", {{-4, 0, -4}, {4, 0, -4}, {4, 0, 4}, {-4, 0, 4}}, {}, {0, 2, 1, 0, 3, 2}, id);
  // A small roof over x in [1.8, 2.2] at y = 1: it hides the lamp straight above (2, 0, 0) only.
  scene.addMesh("roof", {{1.8f, 1, -0.2f}, {2.2f, 1, -0.2f}, {2.2f, 1, 0.2f}, {1.8f, 1, 0.2f}}, {}, {0, 1, 2, 0, 2, 3}, id);
  PunctualLight lamp, spot, sun;
  lamp.position = {2, 1.5f, 0};
  lamp.intensity = {6, 5, 4};
  spot.kind = PunctualKind::Spot;
  spot.position = {-1, 2, 0.5f};
  spot.direction = {0, -1, 0};
  spot.intensity = {10, 10, 10};
  spot.cosInner = 0.2f, spot.cosOuter = 0.1f;
  sun.kind = PunctualKind::Directional;
  sun.direction = normalize(Vec3(-0.3f, -1.0f, 0.2f));
  sun.intensity = {1, 1.2f, 1.5f};
  scene.addPunctualLight(lamp, "lamp");
  scene.addPunctualLight(spot, "spot");
  scene.addPunctualLight(sun, "sun");
  scene.finalize();
  EmbreeIntersector intersector(scene);
  auto radianceAt = [&](Vec3 p, int shadowRays, uint32_t stream) {
    GatherParams params;
    params.punctualShadowRays = shadowRays;
    Ray down{p + Vec3(0, 0.5f, 0.1f), normalize(Vec3(0, -0.5f, -0.1f))};
    CounterRng rng(7, stream, 0);
    return traceToGatherPoint(scene.view(), intersector, params, down, rng).radiance;
  };
  const Vec3 open{-0.5f, 0, 1.0f}, underRoof{2.0f, 0, 0};
  const Vec3 exactOpen = radianceAt(open, 0, 0);
  ASSERT_GT(exactOpen.x, 0.0f);
  Vec3 meanOpen{0, 0, 0};
  for (uint32_t i = 0; i < 4000; ++i) {
    Vec3 one = radianceAt(open, 1, i);
    EXPECT_NEAR(luminance(one), luminance(exactOpen), 1e-5f * luminance(exactOpen)) << i;
    meanOpen += one * (1.0f / 4000);
  }
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(meanOpen[c], exactOpen[c], 0.01f * exactOpen[c]);
  EXPECT_EQ(radianceAt(open, 3, 5), exactOpen);  // a ray per light: the exact evaluation itself
  // Under the roof the exact evaluation is every light's unoccluded contribution but the lamp's.
  const Vec3 exactShaded = radianceAt(underRoof, 0, 0);
  auto lambertian = [](Vec3) { return Vec3(kInvPi); };
  Vec3 visible{0, 0, 0};
  for (uint32_t k = 1; k < 3; ++k)
    visible += punctualContribution(scene.view(), k, underRoof, {0, 1, 0}, {0, 1, 0}, false, 1e-4f, lambertian).value;
  const Vec3 hidden = punctualContribution(scene.view(), 0, underRoof, {0, 1, 0}, {0, 1, 0}, false, 1e-4f, lambertian).value;
  ASSERT_GT(hidden.x, 0.2f * visible.x);
  for (int c = 0; c < 3; ++c) ASSERT_NEAR(exactShaded[c], visible[c], 1e-4f * visible[c]);
  // The sun is never chosen among: its exact, visible contribution is in every estimate.
  const Vec3 sunHere = punctualContribution(scene.view(), 2, underRoof, {0, 1, 0}, {0, 1, 0}, false, 1e-4f, lambertian).value;
  ASSERT_GT(sunHere.x, 0.0f);
  const int paths = 40000;
  for (int rays : {1, 2}) {
    Vec3 mean{0, 0, 0};
    int sunOnly = 0;
    for (int i = 0; i < paths; ++i) {
      Vec3 L = radianceAt(underRoof, rays, uint32_t(i));
      mean += L * (1.0f / paths);
      for (int c = 0; c < 3; ++c) ASSERT_GE(L[c], sunHere[c] * (1 - 1e-4f)) << i;
      sunOnly += luminance(L) < luminance(sunHere) * (1 + 1e-4f);
    }
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c], exactShaded[c], 0.02f * exactShaded[c]) << rays;
    if (rays == 1) {
      EXPECT_GT(sunOnly, paths / 10);  // the rays that chose the hidden lamp
    }
  }
}

// Shadow rays deferred to a kernel of their own (photon/deferred_shadows.h): the gathering code run
// once to record its shadow queries, the queries traced apart, and the code run again with those
// answers gives every pixel bit for bit as tracing in place, with every kind of light (sun, sky,
// point lights chosen among, an area light), an occluder, a mirror and glass on the paths, one
// ray per light (6 queries: the two past kMaxDeferredShadows traced in place) and two samples.
TEST(Lights, DeferredShadowQueriesAnswerAsTracedInPlace) {
  Scene scene;
  Material white, mirror, glass, lamp;
  white.albedo = {0.8f, 0.7f, 0.6f};
  mirror.type = MaterialType::Mirror;
  glass.type = MaterialType::Glass;
  lamp.emission = {4, 4, 4};
  const uint32_t whiteId = scene.addMaterial(white, "floor"), mirrorId = scene.addMaterial(mirror, "mirror");
  const uint32_t glassId = scene.addMaterial(glass, "glass"), lampId = scene.addMaterial(lamp, "lamp");
  scene.addMesh("floor", {{-4, 0, -4}, {4, 0, -4}, {4, 0, 4}, {-4, 0, 4}}, {}, {0, 2, 1, 0, 3, 2}, whiteId);
  scene.addMesh("roof", {{-0.6f, 1, -0.6f}, {0.6f, 1, -0.6f}, {0.6f, 1, 0.6f}, {-0.6f, 1, 0.6f}}, {}, {0, 1, 2, 0, 2, 3}, whiteId);
  scene.addMesh("mirror", {{1.5f, 0, -1}, {1.5f, 0, 1}, {1.5f, 1.2f, 1}, {1.5f, 1.2f, -1}}, {}, {0, 1, 2, 0, 2, 3}, mirrorId);
  scene.addMesh("glass", {{-1.5f, 0, -1}, {-1.5f, 1.2f, -1}, {-1.5f, 1.2f, 1}, {-1.5f, 0, 1}}, {}, {0, 1, 2, 0, 2, 3}, glassId);
  scene.addMesh("panel", {{-0.3f, 2.5f, -0.3f}, {0.3f, 2.5f, -0.3f}, {0.3f, 2.5f, 0.3f}, {-0.3f, 2.5f, 0.3f}}, {},
                {0, 1, 2, 0, 2, 3}, lampId);
  PunctualLight sun;
  sun.kind = PunctualKind::Directional;
  sun.direction = normalize(Vec3(-0.3f, -1.0f, 0.2f));
  sun.intensity = {1, 1.2f, 1.5f};
  scene.addPunctualLight(sun, "sun");
  for (float x : {-1.0f, 0.0f, 1.0f}) {
    PunctualLight point;
    point.position = {x, 0.6f, 0.8f};
    point.intensity = {2, 2, 2};
    scene.addPunctualLight(point, "point");
  }
  SkyLight sky;
  sky.radiance = {0.2f, 0.3f, 0.4f};
  scene.setSky(sky);
  scene.rig.head.position = {0, 2.2f, 3.0f};
  scene.rig.head.orientation = Quat::fromAxisAngle({1, 0, 0}, -0.5f);
  scene.finalize();
  CpuBackend backend(scene);
  const EmbreeIntersector& embree = backend.intersector();
  const SceneView view = scene.view();
  PhotonTraceParams tp;
  tp.photonCount = 1u << 14;
  const HashGrid grid = HashGrid::build(backend.tracePhotons(tp), 0.1f);
  StereoRig rig = scene.rig;
  rig.width = 40, rig.height = 36;
  const EyeCamera camera = rig.eye(Eye::Left);
  const size_t pixels = size_t(camera.width) * camera.height;
  std::vector<ShadowQuery> queries(kMaxDeferredShadows * pixels);
  std::vector<uint8_t> asked(pixels), blocked(kMaxDeferredShadows * pixels);
  const DeferredShadowsView shadows{queries.data(), asked.data(), blocked.data(), pixels};
  for (int shadowRays : {1, 0}) {
    GatherParams params;
    params.density.radius = 0.1f;
    params.punctualShadowRays = shadowRays;
    params.samplesPerPixel = 2;
    size_t differing = 0, overflowing = 0, answered = 0, someBlocked = 0;
    int mostAsked = 0;
    const int perPoint = shadowQueriesPerPoint(view, shadowRays);
    EXPECT_EQ(perPoint, shadowRays == 1 ? 4 : 6);  // sun, one or three points, panel, sky
    for (int y = 0; y < camera.height; ++y)
      for (int x = 0; x < camera.width; ++x) {
        const size_t i = size_t(y) * camera.width + x;
        for (int s = 0; s < params.samplesPerPixel; ++s) {
          PixelSample discarded;
          const RecordedShadows<const EmbreeIntersector&> recorder{embree, queries.data() + i, pixels};
          pixelGatherPoint(view, recorder, params, camera, Eye::Left, x, y, s, StereoReuseView(), discarded);
          asked[i] = uint8_t(recorder.recorded());
          overflowing += recorder.asked > kMaxDeferredShadows;
          mostAsked = std::max(mostAsked, recorder.asked);
          for (int k = 0; k < kMaxDeferredShadows; ++k) answerShadowQuery(embree, shadows, k, i);
          for (int k = 0; k < asked[i]; ++k) answered += 1, someBlocked += blocked[k * pixels + i];
          PixelSample inPlace, replayed;
          const GatherPoint a = pixelGatherPoint(view, embree, params, camera, Eye::Left, x, y, s, StereoReuseView(), inPlace);
          const ReplayedShadows<const EmbreeIntersector&> replay{embree, blocked.data() + i, pixels};
          const GatherPoint b = pixelGatherPoint(view, replay, params, camera, Eye::Left, x, y, s, StereoReuseView(), replayed);
          EXPECT_EQ(replay.asked, recorder.asked);
          const Vec3 la = finishGather(grid.view(), a, params.density), lb = finishGather(grid.view(), b, params.density);
          differing += !(a.radiance == b.radiance && a.weight == b.weight && la == lb && inPlace.firstPrim == replayed.firstPrim);
        }
      }
    EXPECT_EQ(differing, 0u) << "shadow rays per gather point " << shadowRays;
    EXPECT_EQ(mostAsked, perPoint);  // a Lambertian point facing every light asks them all, no more
    EXPECT_GT(answered, pixels);
    EXPECT_GT(someBlocked, answered / 20);  // the roof, the walls and the floor's far side block some
    EXPECT_LT(someBlocked, answered);
    if (shadowRays == 0) EXPECT_GT(overflowing, pixels / 4);  // past kMaxDeferredShadows: traced in place
    else EXPECT_EQ(overflowing, 0u);
  }
}

// The photon map alone (all photons stored) estimates the same irradiance, within its noise.
TEST(Lights, PhotonMapAgreesWithTheDirectIrradiance) {
  PunctualLight lamp;
  lamp.position = {0, 1.5f, 0};
  lamp.intensity = {20, 20, 20};
  LitFloor floor(lamp);
  CpuBackend backend(floor.scene);
  PhotonTraceParams tp;
  tp.photonCount = 1u << 20;
  tp.storeDirect = true;
  tp.maxDepth = 1;
  std::vector<Photon> photons = backend.tracePhotons(tp);
  HashGrid grid = HashGrid::build(photons, 0.1f);
  DensityParams dp;
  dp.radius = 0.1f;
  for (Vec3 p : {Vec3(0, 0, 0), Vec3(0.8f, 0, -0.3f)}) {
    Vec3 toLight = lamp.position - p;
    float r2 = lengthSquared(toLight), expected = 20.0f * (toLight.y / std::sqrt(r2)) / r2;
    float estimate = estimateFluxDensity(grid.view(), p, {0, 1, 0}, dp).x;
    EXPECT_NEAR(estimate, expected, 0.05f * expected) << p.x;
  }
}

// A white floor under a uniform sky L (aimed at a sphere holding the floor): irradiance pi L, so
// the radiance is L, exactly by the cosine-sampled shadow ray and within noise from the photons.
// Rays that escape upwards see L, downwards nothing.
TEST(Lights, UniformSkyLightsAnOpenFloorWithItsRadiance) {
  Scene scene;
  Material white;
  white.albedo = {1, 1, 1};
  uint32_t id = scene.addMaterial(white, "floor");
  scene.addMesh("floor", {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}}, {}, {0, 2, 1, 0, 3, 2}, id);
  SkyLight sky;
  sky.radiance = {0.5f, 1.0f, 2.0f};
  sky.aimCenter = {0, 0, 0};
  sky.aimRadius = 1.5f;
  scene.setSky(sky);
  scene.finalize();
  CpuBackend backend(scene);
  SceneView view = scene.view();
  GatherParams full;
  for (int k = 0; k < 4; ++k) {
    Ray down{{0.2f * k, 1.0f, 0.1f}, normalize(Vec3(0.1f, -1.0f, 0.05f))};
    CounterRng rng(3, uint32_t(k), 0);
    GatherPoint gp = traceToGatherPoint(view, backend.intersector(), full, down, rng);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(gp.radiance[c], sky.radiance[c], 1e-5f);
  }
  CounterRng rng(1, 0, 0);
  Vec3 up = traceToGatherPoint(view, backend.intersector(), full, Ray{{0, 1, 0}, normalize(Vec3(0.3f, 1, 0))}, rng).radiance;
  Vec3 below = traceToGatherPoint(view, backend.intersector(), full, Ray{{3, 1, 0}, normalize(Vec3(0, -1, 0))}, rng).radiance;
  EXPECT_EQ(up, sky.radiance);
  EXPECT_EQ(below, Vec3(0.0f));
  PhotonTraceParams tp;
  tp.photonCount = 1u << 21;
  tp.storeDirect = true;
  tp.maxDepth = 1;
  HashGrid grid = HashGrid::build(backend.tracePhotons(tp), 0.1f);
  DensityParams dp;
  dp.radius = 0.1f;
  for (Vec3 p : {Vec3(0, 0, 0), Vec3(0.5f, 0, -0.4f)}) {
    Vec3 e = estimateFluxDensity(grid.view(), p, {0, 1, 0}, dp);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(e[c], kPi * sky.radiance[c], 0.05f * kPi * sky.radiance[c]) << p.x;
  }
  Vec3 sum{0, 0, 0};
  for (uint32_t i = 0; i < 100000; ++i) sum += emitPhoton(view, PhotonTraceParams{100000}, i).power;
  Vec3 total = scene.totalLightPower();
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], total[c], 1e-3f * total[c]);
}

TEST(Lights, PhotonsCarryTheLightsPower) {
  Scene scene;
  uint32_t id = scene.addMaterial(Material{}, "floor");
  scene.addMesh("floor", {{-4, 0, -4}, {4, 0, -4}, {4, 0, 4}, {-4, 0, 4}}, {}, {0, 2, 1, 0, 3, 2}, id);
  PunctualLight point, sun;
  point.position = {0, 1, 0};
  point.intensity = {3, 2, 1};
  sun.kind = PunctualKind::Directional;
  sun.intensity = {1, 1, 1};
  scene.addPunctualLight(point, "point");
  scene.addPunctualLight(sun, "sun");
  scene.finalize();
  PhotonTraceParams tp;
  tp.photonCount = 200000;
  Vec3 sum{0, 0, 0};
  for (uint32_t i = 0; i < tp.photonCount; ++i) sum += emitPhoton(scene.view(), tp, i).power;
  Vec3 total = scene.totalLightPower();
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], total[c], 0.01f * total[c]);
}

}  // namespace
}  // namespace pvr

#include <filesystem>
#include <algorithm>
#include <fstream>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "pvr/image/image_io.h"

namespace pvr {
namespace {

// An OBJ with map_Kd and map_d next to it: both images load, the material is a cut-out, and a hit
// reads the texels (colour in the right half, cut out in the left half of the mask).
TEST(SceneImport, ObjTextureAndAlphaMapsLoad) {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / ("pvr_obj_maps_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::vector<unsigned char> colour(8 * 8 * 3), mask(8 * 8 * 3);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      unsigned char* c = &colour[3 * (y * 8 + x)];
      c[0] = 200, c[1] = uint8_t(20 * x), c[2] = uint8_t(20 * y);
      unsigned char* m = &mask[3 * (y * 8 + x)];
      m[0] = m[1] = m[2] = x < 4 ? 0 : 255;
    }
  writePngRgb(colour, 8, 8, (dir / "Colour.png").string());
  writePngRgb(mask, 8, 8, (dir / "mask.png").string());
  std::ofstream(dir / "quad.mtl") << "newmtl leaf\nKd 1 1 1\nd 1\nmap_Kd colour.png\nmap_d mask.png\n";  // case differs: found anyway
  std::ofstream(dir / "quad.obj") << "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                     "usemtl leaf\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
  Scene scene;
  importMeshFile((dir / "quad.obj").string(), scene);
  PunctualLight sun;
  sun.kind = PunctualKind::Directional;
  scene.addPunctualLight(sun, "sun");
  scene.finalize();
  fs::remove_all(dir);
  ASSERT_EQ(scene.textureCount(), 2u);
  const auto& names = scene.materialNames();
  size_t leaf = size_t(std::find(names.begin(), names.end(), "leaf") - names.begin());
  ASSERT_LT(leaf, names.size());
  const Material& m = scene.materials()[leaf];
  ASSERT_TRUE(m.baseColorTexture.present());
  ASSERT_TRUE(m.opacityTexture.present());
  EXPECT_EQ(m.alphaMode, AlphaMode::Mask);
  SceneView v = scene.view();
  // Triangle 0 is (0,0) (1,0) (1,1) in UV: barycentrics (u, v) = weights of vertices 1 and 2.
  // A point at UV (0.8, 0.3) is opaque; (0.2, 0.1) is cut out.
  EXPECT_TRUE(v.alphaPasses(0, 0.5f, 0.3f));   // uv = (0.8, 0.3)
  EXPECT_FALSE(v.alphaPasses(0, 0.1f, 0.1f));  // uv = (0.2, 0.1)
  Vec3 albedo = v.albedoAt(m, 0, 0.5f, 0.3f);
  EXPECT_NEAR(albedo.x, srgb8ToLinear(200), 0.02f);
}

}  // namespace
}  // namespace pvr

namespace pvr {
namespace {

// KHR_texture_transform from the Khronos sample (Debian's assimp-testmodels), read from the
// file's JSON and matched to assimp's reordered materials by name.
TEST(SceneImport, GltfTextureTransformIsRead) {
  const std::string path = "/usr/share/assimp/models/glTF2/textureTransform/TextureTransformTest.gltf";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "assimp-testmodels is not installed";
  Scene scene;
  importMeshFile(path, scene);
  auto material = [&](const std::string& name) -> const Material& { return test::materialNamed(scene, name); };
  EXPECT_FLOAT_EQ(material("Offset U").baseColorTexture.offset.x, 0.5f);
  EXPECT_FLOAT_EQ(material("Offset V").baseColorTexture.offset.y, 0.5f);
  EXPECT_NEAR(material("Rotation").baseColorTexture.rotation, 0.39269908f, 1e-6f);
  EXPECT_FLOAT_EQ(material("Scale").baseColorTexture.scale.x, 1.5f);
  const TextureRef& all = material("All").baseColorTexture;
  EXPECT_FLOAT_EQ(all.offset.x, -0.2f);
  EXPECT_FLOAT_EQ(all.offset.y, -0.1f);
  EXPECT_FLOAT_EQ(all.rotation, 0.3f);
  EXPECT_FLOAT_EQ(all.scale.y, 1.5f);
  EXPECT_FLOAT_EQ(material("Correct").baseColorTexture.scale.x, 1.0f);  // no extension: identity
}

// The transform applies to every texture slot: the same file with "Offset U"'s texture also used
// as its normal, emissive and occlusion maps (written beside the original's images).
TEST(SceneImport, GltfTextureTransformAppliesToEverySlot) {
  namespace fs = std::filesystem;
  const fs::path source = "/usr/share/assimp/models/glTF2/textureTransform";
  if (!fs::exists(source / "TextureTransformTest.gltf")) GTEST_SKIP() << "assimp-testmodels is not installed";
  const fs::path dir = fs::temp_directory_path() / ("pvr_transform_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (const auto& entry : fs::directory_iterator(source))
    if (entry.path().extension() != ".gltf") fs::copy_file(entry.path(), dir / entry.path().filename(), fs::copy_options::overwrite_existing);
  nlohmann::json doc = nlohmann::json::parse(std::ifstream(source / "TextureTransformTest.gltf"));
  for (auto& m : doc["materials"])
    if (m["name"] == "Offset U") {
      const nlohmann::json info = m["pbrMetallicRoughness"]["baseColorTexture"];
      m["normalTexture"] = info;
      m["emissiveTexture"] = info;
      m["occlusionTexture"] = info;
      m["pbrMetallicRoughness"]["metallicRoughnessTexture"] = info;
    }
  std::ofstream(dir / "slots.gltf") << doc.dump();
  Scene scene;
  importMeshFile((dir / "slots.gltf").string(), scene);
  const Material& m = test::materialNamed(scene, "Offset U");
  EXPECT_EQ(m.type, MaterialType::Microfacet);
  for (const TextureRef* ref : {&m.normalTexture, &m.emissiveTexture, &m.occlusionTexture, &m.metallicRoughnessTexture}) {
    EXPECT_TRUE(ref->present());
    EXPECT_FLOAT_EQ(ref->offset.x, 0.5f);
  }
  fs::remove_all(dir);
}

// Khronos' clear-coat test scene: its metallic-roughness and emissive textures load, its
// materials are microfacet with their factors (the coat itself is not modelled).
TEST(SceneImport, GltfMetallicRoughnessAndEmissiveTexturesLoad) {
  const std::string path = "/usr/share/assimp/models/glTF2/ClearCoat-glTF/ClearCoatTest.gltf";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "assimp-testmodels is not installed";
  Scene scene;
  importMeshFile(path, scene);
  auto material = [&](const std::string& name) -> const Material& { return test::materialNamed(scene, name); };
  const Material& base = material("Simple_Base");
  EXPECT_EQ(base.type, MaterialType::Microfacet);
  EXPECT_NEAR(base.roughness, 0.44f, 1e-6f);
  EXPECT_EQ(base.metallic, 0.0f);
  EXPECT_TRUE(material("RoughVariations_Coating").metallicRoughnessTexture.present());
  const Material& label = material("LabelMaterial");
  EXPECT_TRUE(label.emissiveTexture.present());
  EXPECT_EQ(label.emission, Vec3(1.0f));
  EXPECT_TRUE(material("BaseNorm_Base").normalTexture.present());
}

// The Khronos cameras sample: a bare glTF file is viewed from its first perspective camera (at
// (0.5, 0.5, 3), looking down -Z), not from the default framing; the import's scale, rotation and
// translation move the camera with the mesh.
TEST(SceneImport, GltfCameraIsTheViewpoint) {
  const std::string path = "/usr/share/assimp/models/glTF2/cameras/Cameras.gltf";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "assimp-testmodels is not installed";
  const Scene scene = loadScene(path);
  auto near = [](Vec3 a, Vec3 b) { return length(a - b) < 1e-5f; };
  EXPECT_TRUE(near(scene.rig.head.position, {0.5f, 0.5f, 3.0f}));
  EXPECT_TRUE(near(scene.rig.head.toWorldDir({0, 0, -1}), {0, 0, -1}));
  EXPECT_TRUE(near(scene.rig.head.toWorldDir({0, 1, 0}), {0, 1, 0}));
  ImportOptions moved;
  moved.scale = {2, 2, 2};
  moved.rotation = Quat::fromAxisAngle({0, 1, 0}, 0.5f * kPi);  // -Z turns to -X
  moved.translation = {1, 0, 0};
  Scene other;
  const std::optional<FileCamera> camera = importMeshFile(path, other, moved);
  ASSERT_TRUE(camera.has_value());
  EXPECT_TRUE(near(camera->pose.position, {1.0f + 6.0f, 1.0f, -1.0f})) << camera->pose.position.x;
  EXPECT_TRUE(near(camera->pose.toWorldDir({0, 0, -1}), {-1, 0, 0}));
  // A JSON scene takes it with "use_camera"; its "camera" entry may still change the rest.
  const std::filesystem::path json =
      std::filesystem::temp_directory_path() / ("pvr_use_camera_" + std::to_string(::getpid()) + ".json");
  std::ofstream(json) << R"({"meshes": [{"file": ")" << path << R"(", "translate": [0, 0, 1], "use_camera": true}],
                             "lights": [{"sun": [0, 1, 0], "irradiance": [1, 1, 1]}], "camera": {"ipd": 0.07}})";
  const Scene fromJson = loadScene(json.string());
  std::filesystem::remove(json);
  EXPECT_TRUE(near(fromJson.rig.head.position, {0.5f, 0.5f, 4.0f}));
  EXPECT_FLOAT_EQ(fromJson.rig.ipd, 0.07f);
}

// A camera under rotated and translated parents: its world pose is the product of the node
// transforms (TRS and "matrix" nodes); an orthographic camera is passed over; no camera gives none.
TEST(SceneImport, GltfCameraTakesItsNodesWorldTransform) {
  namespace fs = std::filesystem;
  const fs::path box = "/usr/share/assimp/models/glTF2/BoxTextured-glTF/BoxTextured.gltf";
  if (!fs::exists(box)) GTEST_SKIP() << "assimp-testmodels is not installed";
  const fs::path dir = fs::temp_directory_path() / ("pvr_camera_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (const auto& entry : fs::directory_iterator(box.parent_path()))
    fs::copy_file(entry.path(), dir / entry.path().filename(), fs::copy_options::overwrite_existing);
  nlohmann::json doc = nlohmann::json::parse(std::ifstream(box));
  const size_t first = doc["nodes"].size();
  // rig (turned 90 degrees about +Y, at (0, 0, 4)) -> arm (a matrix: translate (0, 1, 0)) -> camera
  // at (0, 0, 2) locally: world (2, 1, 4), looking down -X.
  const float h = std::sqrt(0.5f);
  doc["nodes"].push_back({{"name", "rig"}, {"rotation", {0, h, 0, h}}, {"translation", {0, 0, 4}}, {"children", {first + 1}}});
  doc["nodes"].push_back({{"name", "arm"}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 1, 0, 1}},
                          {"children", {first + 2}}});
  doc["nodes"].push_back({{"name", "eye"}, {"translation", {0, 0, 2}}, {"camera", 1}});
  doc["nodes"].push_back({{"name", "flat"}, {"camera", 0}});
  doc["cameras"] = {{{"type", "orthographic"}, {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.1}, {"zfar", 9}}}},
                    {{"type", "perspective"}, {"name", "walk"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}}};
  doc["scenes"][0]["nodes"] = {first + 3, 0, first};
  std::ofstream(dir / "rigged.gltf") << doc.dump();
  Scene scene;
  const std::optional<FileCamera> camera = importMeshFile((dir / "rigged.gltf").string(), scene);
  ASSERT_TRUE(camera.has_value());
  EXPECT_EQ(camera->name, "walk");
  EXPECT_LT(length(camera->pose.position - Vec3(2, 1, 4)), 1e-5f);
  EXPECT_LT(length(camera->pose.toWorldDir({0, 0, -1}) - Vec3(-1, 0, 0)), 1e-5f);
  EXPECT_LT(length(camera->pose.toWorldDir({0, 1, 0}) - Vec3(0, 1, 0)), 1e-5f);
  Scene plain;
  EXPECT_FALSE(importMeshFile(box.string(), plain).has_value());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pvr

namespace pvr {
namespace {

// A constant normal map tilting the normal by 30 degrees towards +u: under a light straight above
// the plane the cosine becomes that of the decoded normal's tilt; a flat map (0.5, 0.5, 1)
// changes nothing; and a bump map's slopes lean the normal away from the rise.
TEST(NormalMaps, ConstantTiltScalesTheCosineAsExpected) {
  auto floorWith = [](uint32_t texel, Vec3* decoded) {
    Scene scene;
    Material m;
    m.albedo = {1, 1, 1};
    m.normalTexture.texture = int32_t(scene.addTexture("n", 2, 2, std::vector<uint32_t>(4, texel), false));
    uint32_t id = scene.addMaterial(m, "floor");
    // Floor y = 0 facing +Y; u along +x, v along +z (so "up the image", -v, is -z).
    std::vector<Vec2> uvs[2] = {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {}};
    scene.addMesh("floor", {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}}, {}, uvs, {0, 2, 1, 0, 3, 2}, id);
    PunctualLight lamp;
    lamp.position = {0, 2, 0};
    lamp.intensity = {10, 10, 10};
    scene.addPunctualLight(lamp, "lamp");
    scene.finalize();
    if (decoded) {
      Rgba c = decodeTexel(texel, false);
      *decoded = normalize(Vec3(2 * c.rgb.x - 1, 2 * c.rgb.y - 1, 2 * c.rgb.z - 1));
    }
    return scene;
  };
  auto code = [](float c) { return uint32_t(std::lround(255.0f * (0.5f * c + 0.5f))); };
  const float tilt = 30.0f * kPi / 180.0f;
  const uint32_t tilted = code(std::sin(tilt)) | code(0.0f) << 8 | code(std::cos(tilt)) << 16 | 255u << 24;
  const uint32_t flat = code(0.0f) | code(0.0f) << 8 | code(1.0f) << 16 | 255u << 24;
  Vec3 n;
  Scene scene = floorWith(tilted, &n);
  SceneView v = scene.view();
  Hit hit;
  hit.primId = 0, hit.u = 0.3f, hit.v = 0.3f, hit.t = 1.0f;
  SurfacePoint sp = v.surfacePoint(hit);
  // Tangent space (x along +u = +x, y up the image = -z, z = +Y): world (n.x, n.z, -n.y).
  EXPECT_NEAR(sp.shadingNormal.x, n.x, 1e-5f);
  EXPECT_NEAR(sp.shadingNormal.y, n.z, 1e-5f);
  EXPECT_NEAR(sp.shadingNormal.z, -n.y, 1e-5f);
  EmbreeIntersector intersector(scene);
  GatherParams params;
  CounterRng rng(1, 0, 0);
  Vec3 p = v.surfacePoint(hit).position;
  Ray down{p + Vec3(0, 1.0f, 0.2f), normalize(Vec3(0, -1.0f, -0.2f))};
  float r2 = lengthSquared(Vec3(0, 2, 0) - p);
  Vec3 wi = normalize(Vec3(0, 2, 0) - p);
  float L = traceToGatherPoint(v, intersector, params, down, rng).radiance.x;
  EXPECT_NEAR(L, 10.0f * dot(sp.shadingNormal, wi) / r2 / kPi, 1e-4f * L);
  EXPECT_LT(dot(sp.shadingNormal, Vec3(0, 1, 0)), 0.9f);  // really tilted

  Scene plain = floorWith(flat, nullptr);
  EXPECT_NEAR(plain.view().surfacePoint(hit).shadingNormal.y, 1.0f, 1e-3f);
}

}  // namespace
}  // namespace pvr

#include "pvr/scene/texture_file.h"

namespace pvr {
namespace {

TEST(NormalMaps, BumpSlopesLeanTheNormalAwayFromTheRise) {
  Scene scene;
  std::vector<uint32_t> ramp;  // height rises along +x (+u), flat along y
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) ramp.push_back(uint32_t(20 * x) * 0x010101u | 0xff000000u);
  int32_t height = int32_t(scene.addTexture("ramp", 8, 8, ramp, false, WrapMode::ClampToEdge, WrapMode::ClampToEdge));
  TextureLoader loader(scene);
  int32_t normals = loader.normalsFromHeight(height, 4.0f);
  ASSERT_GE(normals, 0);
  Rgba c = sampleTexture(scene.textureViews()[size_t(normals)], {0.5f, 0.5f}, 0.0f);
  Vec3 n{2 * c.rgb.x - 1, 2 * c.rgb.y - 1, 2 * c.rgb.z - 1};
  float slope = 4.0f * 20.0f / 255.0f;  // strength x height step per texel
  EXPECT_NEAR(n.x, -slope / std::sqrt(1 + slope * slope), 0.01f);
  EXPECT_NEAR(n.y, 0.0f, 0.01f);
  EXPECT_GT(n.z, 0.0f);
  EXPECT_EQ(loader.normalsFromHeight(-1, 1.0f), -1);
}

}  // namespace
}  // namespace pvr
