// Ray-VR's per-material effect levels (EffectLevel), each by its defining property: raster casts
// no shadow, shadows is gi without its photon-map term, reflections follows mirrors and glass as
// gi does, path converges to the analytic furnace; and the scene format's "effect"/"effects".
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include "pvr/cpu/cpu_backend.h"
#include "pvr/photon/gather.h"
#include "pvr/scene/scene.h"
#include "pvr/util/error.h"
#include "test_scenes.h"

namespace pvr {
namespace {

GatherParams atLevel(EffectLevel level) {
  GatherParams p;
  p.overrideEffects = true;
  p.effects = level;
  return p;
}

// A floor under a point light, and (optionally) a quad between them over x, z in [-0.5, 0.5].
Scene shadowedFloor(bool occluder) {
  Scene scene;
  Material white;
  white.albedo = {1, 1, 1};
  const uint32_t id = scene.addMaterial(white, "floor");
  scene.addMesh("floor", {{-4, 0, -4}, {4, 0, -4}, {4, 0, 4}, {-4, 0, 4}}, {}, {0, 2, 1, 0, 3, 2}, id);
  if (occluder)
    scene.addMesh("occluder", {{-0.5f, 1.5f, -0.5f}, {0.5f, 1.5f, -0.5f}, {0.5f, 1.5f, 0.5f}, {-0.5f, 1.5f, 0.5f}}, {},
                  {0, 2, 1, 0, 3, 2}, id);
  PunctualLight lamp;
  lamp.position = {0, 3, 0};
  lamp.intensity = {10, 10, 10};
  scene.addPunctualLight(lamp, "lamp");
  scene.finalize();
  return scene;
}

// Floor points seen from below the occluder: each point's direct light at `level`.
std::vector<Vec3> floorRadiance(const Scene& scene, EffectLevel level) {
  CpuBackend backend(scene);
  const SceneView view = scene.view();
  std::vector<Vec3> out;
  for (int i = 0; i < 24; ++i)
    for (int j = 0; j < 24; ++j) {
      const Vec3 p{-0.9f + 1.8f * (i + 0.5f) / 24.0f, 0.0f, -0.9f + 1.8f * (j + 0.5f) / 24.0f};
      const Vec3 eye = p + Vec3{0.0f, 0.4f, 0.3f};
      CounterRng rng(1, uint32_t(i * 24 + j), 0);
      out.push_back(traceToGatherPoint(view, backend.intersector(), atLevel(level), Ray{eye, normalize(p - eye)}, rng).radiance);
    }
  return out;
}

TEST(EffectLevels, RasterCastsNoShadowsAndShadowsDoes) {
  const Scene open = shadowedFloor(false), blocked = shadowedFloor(true);
  const std::vector<Vec3> rasterOpen = floorRadiance(open, EffectLevel::Raster);
  const std::vector<Vec3> rasterBlocked = floorRadiance(blocked, EffectLevel::Raster);
  const std::vector<Vec3> shadowsOpen = floorRadiance(open, EffectLevel::Shadows);
  const std::vector<Vec3> shadowsBlocked = floorRadiance(blocked, EffectLevel::Shadows);
  int shadowed = 0;
  for (size_t k = 0; k < rasterOpen.size(); ++k) {
    EXPECT_EQ(rasterBlocked[k], rasterOpen[k]) << "raster: a blocked point is as bright as an unblocked one";
    EXPECT_EQ(shadowsOpen[k], rasterOpen[k]) << "with nothing in the way both levels see the same light";
    EXPECT_GT(luminance(rasterOpen[k]), 0.0f);
    if (luminance(shadowsBlocked[k]) == 0.0f) ++shadowed;
    else EXPECT_EQ(shadowsBlocked[k], shadowsOpen[k]);
  }
  EXPECT_GT(shadowed, 100) << "the occluder's shadow falls on the points under it";
}

// Every pixel of a small Cornell view (diffuse walls and blocks; mirror and glass in the caustics
// box), traced to its gather point at each level with the same random numbers.
struct LevelPoints {
  std::vector<GatherPoint> points[kEffectLevels];
  std::vector<bool> specularFirst;
};

LevelPoints levelPoints(const char* name) {
  Scene scene = loadScene(name);
  CpuBackend backend(scene);
  const SceneView view = scene.view();
  StereoRig rig = scene.rig;
  rig.width = 48, rig.height = 54;
  const EyeCamera cam = rig.eye(Eye::Left);
  LevelPoints out;
  for (int y = 0; y < rig.height; ++y)
    for (int x = 0; x < rig.width; ++x) {
      const Ray ray = cam.generateRay(x + 0.5f, y + 0.5f);
      Hit first;
      backend.intersector().intersect(ray, INFINITY, first);
      out.specularFirst.push_back(first.valid() && scene.materials()[scene.materialIds()[first.primId]].isSpecular());
      for (int l = 0; l < kEffectLevels; ++l) {
        CounterRng rng(7, uint32_t(y * rig.width + x), 0);
        out.points[l].push_back(traceToGatherPoint(view, backend.intersector(), atLevel(EffectLevel(l)), ray, rng));
      }
    }
  return out;
}

TEST(EffectLevels, ShadowsIsGiWithoutItsPhotonMapTerm) {
  const LevelPoints lp = levelPoints("cornell");
  const auto& gi = lp.points[int(EffectLevel::Gi)];
  const auto& shadows = lp.points[int(EffectLevel::Shadows)];
  size_t estimated = 0;
  for (size_t i = 0; i < gi.size(); ++i) {
    EXPECT_EQ(shadows[i].radiance, gi[i].radiance) << "pixel " << i;
    EXPECT_FALSE(shadows[i].needsEstimate());
    estimated += gi[i].needsEstimate();
  }
  EXPECT_GT(estimated, gi.size() / 4) << "gi estimates where the walls are seen";
}

TEST(EffectLevels, ReflectionsFollowsMirrorsAndGlassAsGiDoes) {
  const LevelPoints lp = levelPoints("cornell-caustics");
  const auto& gi = lp.points[int(EffectLevel::Gi)];
  const auto& reflections = lp.points[int(EffectLevel::Reflections)];
  const auto& shadows = lp.points[int(EffectLevel::Shadows)];
  size_t specular = 0, differsFromShadows = 0;
  for (size_t i = 0; i < gi.size(); ++i) {
    EXPECT_EQ(reflections[i].radiance, gi[i].radiance) << "pixel " << i;
    EXPECT_FALSE(reflections[i].needsEstimate());
    if (!lp.specularFirst[i]) {
      EXPECT_EQ(reflections[i].radiance, shadows[i].radiance) << "pixel " << i;
      continue;
    }
    ++specular;
    differsFromShadows += !(reflections[i].radiance == shadows[i].radiance);
  }
  EXPECT_GT(specular, 50u);
  EXPECT_GT(differsFromShadows, specular / 2) << "below reflections, mirrors and glass are shaded by their tint instead";
}

// The denoiser divides a pixel by the reflectance of the surface its path ends on, so that it
// filters light, not texture. Every level ends its paths where gi does (on the Cornell box's
// diffuse walls and blocks, and through its mirror and glass from reflections up), and must give
// the same reflectance there, although below gi the point carries no estimate.
TEST(EffectLevels, EveryLevelDemodulatesByTheSurfacesReflectance) {
  for (const char* name : {"cornell", "cornell-caustics"}) {
    const LevelPoints lp = levelPoints(name);
    const auto& gi = lp.points[int(EffectLevel::Gi)];
    size_t surfaces = 0;
    for (size_t i = 0; i < gi.size(); ++i) {
      if (gi[i].needsEstimate()) ++surfaces;
      for (EffectLevel level : {EffectLevel::Raster, EffectLevel::Shadows, EffectLevel::Reflections, EffectLevel::Path}) {
        if (lp.specularFirst[i] && level < EffectLevel::Reflections) continue;  // shaded by the tint, where gi follows
        const Vec3 expected = gi[i].reflectance, got = lp.points[int(level)][i].reflectance;
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(got[c], expected[c], 1e-6f) << name << " pixel " << i << " at " << effectLevelName(level);
      }
      if (!gi[i].needsEstimate()) continue;
      // At gi: the path's throughput times the albedo, the weight times pi on these Lambertian walls.
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(gi[i].reflectance[c], gi[i].weight[c] * kPi, 1e-6f);
      EXPECT_GT(luminance(gi[i].reflectance), 0.0f);
    }
    EXPECT_GT(surfaces, gi.size() / 4) << name;
  }
}

// A rough glass panel (a microfacet surface that mostly transmits): below reflections nothing is
// followed, so every eye path ends on the panel with its light estimated there (none goes black
// on a follow decision that has no lobe to follow).
TEST(EffectLevels, BelowReflectionsRoughGlassIsShadedWhereItIsHit) {
  Scene scene;
  Material frosted;
  frosted.type = MaterialType::Microfacet;
  frosted.transmission = 1.0f;
  frosted.roughness = 0.6f;
  frosted.albedo = {0.9f, 0.9f, 0.9f};
  const uint32_t id = scene.addMaterial(frosted, "frosted");
  scene.addMesh("panel", {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, {}, {0, 1, 2, 0, 2, 3}, id);
  PunctualLight lamp;
  lamp.position = {0, 0, 2};
  scene.addPunctualLight(lamp, "lamp");
  scene.finalize();
  CpuBackend backend(scene);
  for (EffectLevel level : {EffectLevel::Raster, EffectLevel::Shadows}) {
    int lit = 0;
    for (int i = 0; i < 400; ++i) {
      const Vec3 target{-0.8f + 1.6f * float(i % 20) / 19.0f, -0.8f + 1.6f * float(i / 20) / 19.0f, 0.0f};
      const Vec3 eye{0.1f, 0.2f, 1.0f};
      CounterRng rng(3, uint32_t(i), 0);
      const GatherPoint g = traceToGatherPoint(scene.view(), backend.intersector(), atLevel(level), Ray{eye, normalize(target - eye)}, rng);
      EXPECT_NEAR(g.position.z, 0.0f, 1e-4f) << effectLevelName(level) << " ray " << i << " ends on the panel";
      EXPECT_GT(length(g.normal), 0.5f);
      lit += luminance(g.radiance) > 0.0f;
      EXPECT_LT(luminance(g.radiance), 10.0f) << "no pixel scaled up by a rare choice";
    }
    EXPECT_EQ(lit, 400) << effectLevelName(level);
  }
}

// The furnace (a closed cube, albedo rho, emission Le everywhere) has radiance Le / (1 - rho):
// path tracing with next-event estimation must find it without a photon map.
TEST(EffectLevels, PathConvergesToTheFurnaceRadiance) {
  for (float rho : {0.3f, 0.7f}) {
    Scene scene = test::furnaceBox(rho, 1.0f);
    CpuBackend backend(scene);
    const SceneView view = scene.view();
    GatherParams p = atLevel(EffectLevel::Path);
    p.pathDepth = 48;  // rho^48 of the answer is cut off: negligible
    std::mt19937 rng(3);
    std::normal_distribution<float> normal;
    Vec3 sum{0, 0, 0};
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      const Vec3 dir = normalize(Vec3(normal(rng), normal(rng), normal(rng)));
      CounterRng counter(5, uint32_t(i), 0);
      const GatherPoint g = traceToGatherPoint(view, backend.intersector(), p, Ray{{0, 0, 0}, dir}, counter);
      EXPECT_FALSE(g.needsEstimate());
      sum += g.radiance;
    }
    const float expected = 1.0f / (1.0f - rho);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c] / n, expected, 0.02f * expected) << "rho " << rho << " channel " << c;
  }
}

TEST(EffectLevels, NamesRoundTrip) {
  for (int l = 0; l < kEffectLevels; ++l) {
    EffectLevel back;
    ASSERT_TRUE(effectLevelFromName(effectLevelName(EffectLevel(l)), back));
    EXPECT_EQ(int(back), l);
  }
  EffectLevel ignored;
  EXPECT_FALSE(effectLevelFromName("ambient", ignored));
}

// Loading `path` throws pvr::Error with `expected` in its message.
void expectSceneError(const std::string& path, const std::string& expected) {
  try {
    loadScene(path);
    ADD_FAILURE() << path << " loaded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
}

// The scene format: "effect" on a mesh entry sets every material that file brought; "effects"
// sets materials by name; unknown levels and names are errors naming them.
TEST(EffectLevels, SceneFilesSetThemPerMeshAndPerMaterialName) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "pvr_effects_test";
  std::filesystem::create_directories(dir);
  auto write = [&](const char* name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  const std::string data = PVR_TEST_DATA;
  const std::string good = write("good.json", R"({"base": "cornell", "meshes": [{"file": ")" + data +
                                                  R"(/box.obj", "effect": "shadows"}], "effects": {"light": "raster"}})");
  Scene scene = loadScene(good);
  size_t shadows = 0, raster = 0, gi = 0;
  for (size_t i = 0; i < scene.materials().size(); ++i) {
    const EffectLevel l = scene.materials()[i].effect;
    shadows += l == EffectLevel::Shadows, raster += l == EffectLevel::Raster, gi += l == EffectLevel::Gi;
    if (scene.materialNames()[i] == "light") {
      EXPECT_EQ(int(l), int(EffectLevel::Raster));
    }
  }
  EXPECT_GT(shadows, 0u);
  EXPECT_GT(raster, 0u);
  EXPECT_GT(gi, 0u) << "the base scene's materials keep the default";
  const std::string badLevel = write("bad_level.json", R"({"base": "cornell", "effects": {"light": "ambient"}})");
  const std::string badName = write("bad_name.json", R"({"base": "cornell", "effects": {"statues": "reflections"}})");
  expectSceneError(badLevel, "must be raster, shadows, reflections, gi or path");
  expectSceneError(badName, "'statues'");
  std::filesystem::remove_all(dir);
}

// An effect group's level (GatherParams::groupEffects, what --effects GROUP=LEVEL and the budget
// controller set) is the level its materials would have of their own: same gather points, ray for
// ray, as a scene whose mirror and glass carry that level.
TEST(EffectLevels, AGroupsLevelIsItsMaterialsOwn) {
  const Scene grouped = loadScene("cornell-caustics");
  const int specular = grouped.effectGroupIndex("specular");
  ASSERT_GT(specular, 0);
  EXPECT_EQ(grouped.effectGroupNames()[0], "rest");
  Scene own = grouped;
  for (const char* name : {"mirror", "glass"}) own.setEffect(uint32_t(own.materialIndex(name)), EffectLevel::Raster);
  CpuBackend groupedBackend(grouped), ownBackend(own);
  GatherParams byGroup;
  byGroup.groupEffects[specular] = uint8_t(EffectLevel::Raster);
  const GatherParams byMaterial;
  StereoRig rig = grouped.rig;
  rig.width = 40, rig.height = 45;
  const EyeCamera cam = rig.eye(Eye::Left);
  size_t differFromGi = 0;
  for (int y = 0; y < rig.height; ++y)
    for (int x = 0; x < rig.width; ++x) {
      const Ray ray = cam.generateRay(x + 0.5f, y + 0.5f);
      CounterRng a(3, uint32_t(y * rig.width + x), 0), b = a, c = a;
      const GatherPoint g = traceToGatherPoint(grouped.view(), groupedBackend.intersector(), byGroup, ray, a);
      const GatherPoint m = traceToGatherPoint(own.view(), ownBackend.intersector(), byMaterial, ray, b);
      const GatherPoint gi = traceToGatherPoint(grouped.view(), groupedBackend.intersector(), GatherParams(), ray, c);
      ASSERT_EQ(g.radiance, m.radiance) << x << "," << y;
      ASSERT_EQ(g.needsEstimate(), m.needsEstimate());
      differFromGi += !(g.radiance == gi.radiance);
    }
  EXPECT_GT(differFromGi, 25u) << "the spheres' pixels change with their group's level";
  // The override wins over a group's level.
  GatherParams both = byGroup;
  both.overrideEffects = true;
  both.effects = EffectLevel::Gi;
  EXPECT_EQ(int(effectLevelOf(both, grouped.materials()[size_t(grouped.materialIndex("mirror"))])), int(EffectLevel::Gi));
  EXPECT_EQ(int(effectLevelOf(byGroup, grouped.materials()[size_t(grouped.materialIndex("mirror"))])), int(EffectLevel::Raster));
  EXPECT_EQ(int(effectLevelOf(byGroup, grouped.materials()[size_t(grouped.materialIndex("white"))])), int(EffectLevel::Gi));
}

// "effect_groups" in a scene file: materials by name into named groups; errors name the problem.
TEST(EffectLevels, SceneFilesNameEffectGroups) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "pvr_effect_groups_test";
  std::filesystem::create_directories(dir);
  auto write = [&](const char* name, const std::string& groups) {
    std::ofstream(dir / name) << R"({"base": "cornell", "effect_groups": )" + groups + "}";
    return (dir / name).string();
  };
  const Scene scene = loadScene(write("good.json", R"({"colour": ["red", "green"], "lamp": ["light"]})"));
  ASSERT_EQ(scene.effectGroupNames().size(), 3u);
  const int colour = scene.effectGroupIndex("colour"), lamp = scene.effectGroupIndex("lamp");
  EXPECT_EQ(scene.materials()[size_t(scene.materialIndex("red"))].effectGroup, uint32_t(colour));
  EXPECT_EQ(scene.materials()[size_t(scene.materialIndex("green"))].effectGroup, uint32_t(colour));
  EXPECT_EQ(scene.materials()[size_t(scene.materialIndex("light"))].effectGroup, uint32_t(lamp));
  EXPECT_EQ(scene.materials()[size_t(scene.materialIndex("white"))].effectGroup, 0u);
  expectSceneError(write("unknown.json", R"({"statues": ["marble"]})"), "'marble'");
  expectSceneError(write("twice.json", R"({"a": ["red"], "b": ["red"]})"), "two effect groups");
  expectSceneError(write("rest.json", R"({"rest": ["red"]})"), "reserved");
  expectSceneError(write("empty.json", R"({"a": []})"), "must list material names");
  expectSceneError(write("list.json", R"(["red"])"), "'effect_groups' must map");
  Scene many = loadScene("cornell");
  for (int g = 1; g < kMaxEffectGroups; ++g) many.addEffectGroup("g" + std::to_string(g));
  EXPECT_THROW(many.addEffectGroup("one too many"), Error);
  EXPECT_THROW(many.addEffectGroup("g1"), Error);
  EXPECT_THROW(many.setEffectGroup(0, kMaxEffectGroups), Error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace pvr
