// Scene import (glTF through assimp, OBJ/MTL, JSON scene files) with the material mapping, and
// every bad-input case at the library level: each must throw pvr::Error with a clear message.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>

#include "pvr/render/renderer.h"
#include "pvr/scene/scene.h"
#include "pvr/util/error.h"
#include "pvr/util/json_number.h"
#include "test_scenes.h"

namespace pvr {
namespace {

const std::string kData = PVR_TEST_DATA;

using test::materialNamed;

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(SceneImport, GltfMaterialsMapToPhotonvrMaterials) {
  Scene s = loadScene(kData + "/quad_scene.gltf");
  EXPECT_EQ(s.triangleCount(), 8u);
  EXPECT_EQ(s.lightTriangleCount(), 2u);
  const Material& floor = materialNamed(s, "floor");
  EXPECT_EQ(floor.type, MaterialType::Microfacet);  // glTF: a dielectric layer over the diffuse base
  EXPECT_EQ(floor.metallic, 0.0f);
  EXPECT_EQ(floor.roughness, 1.0f);
  EXPECT_NEAR(floor.specularF0, 0.04f, 1e-6f);
  EXPECT_EQ(floor.albedo, Vec3(0.5f, 0.25f, 0.125f));
  EXPECT_EQ(materialNamed(s, "lamp").emission, Vec3(1.0f, 0.5f, 0.25f));
  EXPECT_EQ(materialNamed(s, "chrome").type, MaterialType::Mirror);
  const Material& glass = materialNamed(s, "glass");
  EXPECT_EQ(glass.type, MaterialType::Glass);
  EXPECT_NEAR(glass.ior, 1.45f, 1e-6f);
}

TEST(SceneImport, ObjMtlMaterialsMapToPhotonvrMaterials) {
  Scene s = loadScene(kData + "/box.obj");
  EXPECT_EQ(s.triangleCount(), 8u);
  EXPECT_EQ(materialNamed(s, "white").albedo, Vec3(0.6f, 0.5f, 0.4f));
  EXPECT_EQ(materialNamed(s, "lamp").emission, Vec3(8, 6, 4));
  const Material& chrome = materialNamed(s, "chrome");
  EXPECT_EQ(chrome.type, MaterialType::Mirror);
  EXPECT_EQ(chrome.albedo, Vec3(0.9f, 0.8f, 0.7f));
  EXPECT_EQ(materialNamed(s, "glass").type, MaterialType::Glass);
  EXPECT_NEAR(materialNamed(s, "glass").ior, 1.33f, 1e-6f);
}

TEST(SceneImport, JsonSceneFilePlacesMeshesAndSetsTheRig) {
  Scene s = loadScene(kData + "/scene.json");
  EXPECT_EQ(s.triangleCount(), 10u);
  EXPECT_EQ(s.lightTriangleCount(), 4u);
  EXPECT_EQ(materialNamed(s, "lamp").emission, Vec3(20.0f, 10.0f, 5.0f));  // emission_scale 20
  Bounds3 b = s.bounds();
  EXPECT_NEAR(b.lower.z, -2.0f, 1e-6f);  // translated by -1
  EXPECT_NEAR(s.rig.ipd, 0.07f, 1e-7f);
  EXPECT_EQ(s.rig.width, 64);
  EXPECT_EQ(s.rig.height, 72);
  EXPECT_NEAR(s.rig.fov[0].angleLeft, -50.0f * kPi / 180.0f, 1e-6f);
  EXPECT_NEAR(s.rig.fov[1].angleRight, 50.0f * kPi / 180.0f, 1e-6f);
  EXPECT_NEAR(s.rig.head.position.z, 1.5f, 1e-6f);
}

TEST(SceneImport, NanAndDegenerateTrianglesAreSkippedAndCounted) {
  Scene s = loadScene(kData + "/nan_and_degenerate.obj");
  EXPECT_EQ(s.triangleCount(), 2u);
  EXPECT_EQ(s.skippedTriangles(), 2u);
  Scene manual;
  uint32_t m = manual.addMaterial(Material{}, "m");
  manual.addMesh("bad", {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, NAN, 0}, {INFINITY, 0, 0}}, {}, {0, 1, 2, 0, 3, 1, 4, 1, 0}, m);
  EXPECT_EQ(manual.triangleCount(), 0u);
  EXPECT_EQ(manual.skippedTriangles(), 3u);
  EXPECT_NE(errorOf([&] { manual.finalize(); }).find("no valid triangles"), std::string::npos);
}

TEST(SceneErrors, EachBadInputThrowsAClearError) {
  struct Case {
    std::string input, expected;
  } cases[] = {
      {kData + "/missing.obj", "no such file"},
      {kData + "/not_a_scene.txt", "unsupported scene format '.txt'"},
      {kData + "/malformed.json", "malformed JSON"},
      {kData + "/malformed.gltf", "cannot read"},
      {kData + "/primitive_without_positions.gltf", "mesh 0 primitive 0 has no POSITION attribute"},
      {kData + "/invalid_utf8.gltf", "not valid JSON (at byte"},
      {kData + "/image_mime_type_without_slash.gltf", "image 0 has a mimeType that is not a MIME type"},
      {kData + "/no_light.json", "has no light"},
      {"cornel", "no such file or built-in scene"},
  };
  for (const Case& c : cases) {
    std::string message = errorOf([&] { loadScene(c.input); });
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.input << " gave: '" << message << "'";
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line";
  }
}

// JSON numbers outside the C++ type they fill: nlohmann's get<T>() would cast, which is undefined
// (the sanitizer suite runs this). Scene files reject them by name; glTF extension values that
// do not fit are dropped with the extensions, as assimp keeps the rest of the file.
TEST(SceneErrors, NumbersOutsideTheirTypesAreRejectedNotCast) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "pvr_scene_numbers";
  std::filesystem::create_directories(dir);
  auto sceneWithCamera = [&](const std::string& name, const std::string& camera) {
    const std::string path = (dir / name).string();
    std::ofstream(path) << R"({"base": "cornell", "camera": )" << camera << "}";
    return errorOf([&] { loadScene(path); });
  };
  EXPECT_NE(sceneWithCamera("ipd.json", R"({"ipd": 1e300})").find("camera.ipd must be a finite number"), std::string::npos);
  EXPECT_NE(sceneWithCamera("pos.json", R"({"position": [0, -1e39, 0]})").find("must be a finite number"), std::string::npos);
  for (const char* size : {"[1e300, 64]", "[-1, 64]", "[64, 4294967360]", "[64.5, 64]"})
    EXPECT_NE(sceneWithCamera("size.json", std::string(R"({"eye_size": )") + size + "}").find("camera.eye_size must be"),
              std::string::npos) << size;
  EXPECT_EQ(sceneWithCamera("fine.json", R"({"eye_size": [64, 48]})"), "");
  std::filesystem::remove_all(dir);

  Scene s = loadScene(kData + "/../fuzz/regressions/mesh/gltf-numbers-outside-their-types.gltf");
  EXPECT_EQ(s.triangleCount(), 8u);
  const Vec3 emission = materialNamed(s, "floor").emission;  // factor 0.25, strength 1e300 dropped
  EXPECT_TRUE(std::isfinite(emission.x) && emission.x <= 0.25f) << emission.x;
  // An accessor's componentType of 1e20 (read before assimp, to check the accessor's range): a
  // clear one-line error, never a cast.
  const std::string accessor =
      errorOf([] { loadScene(kData + "/../fuzz/regressions/mesh/gltf-accessor-component-type-1e20.gltf"); });
  EXPECT_FALSE(accessor.empty());
  EXPECT_EQ(accessor.find('\n'), std::string::npos) << accessor;
}

// jsonNumberFits: exactly the values the type holds, whole-valued floats included for integers
// (JSON Schema counts 3.0 as an integer), with the bounds at the type's powers of two.
TEST(SceneErrors, JsonNumbersFitExactlyTheValuesTheirTypeHolds) {
  using nlohmann::json;
  EXPECT_TRUE(jsonNumberFits<int>(json(3.0)));
  EXPECT_FALSE(jsonNumberFits<int>(json(2.5)));
  EXPECT_TRUE(jsonNumberFits<int>(json(2147483647)));
  EXPECT_FALSE(jsonNumberFits<int>(json(2147483648u)));
  EXPECT_TRUE(jsonNumberFits<int>(json(-2147483648.0)));
  EXPECT_FALSE(jsonNumberFits<int>(json(2147483648.0)));
  EXPECT_FALSE(jsonNumberFits<uint32_t>(json(-1)));
  EXPECT_FALSE(jsonNumberFits<uint32_t>(json(1e20)));
  EXPECT_TRUE(jsonNumberFits<uint32_t>(json(4294967295.0)));
  EXPECT_TRUE(jsonNumberFits<int64_t>(json(-9223372036854775808.0)));  // -2^63
  EXPECT_FALSE(jsonNumberFits<int64_t>(json(9223372036854775808.0)));  // 2^63: double(INT64_MAX) rounds to it
  EXPECT_TRUE(jsonNumberFits<uint64_t>(json(18446744073709551615u)));
  EXPECT_FALSE(jsonNumberFits<uint64_t>(json(18446744073709551616.0)));
  EXPECT_TRUE(jsonNumberFits<float>(json(-3e38)));
  EXPECT_FALSE(jsonNumberFits<float>(json(1e39)));
  EXPECT_TRUE(jsonNumberFits<double>(json(1e300)));
  EXPECT_FALSE(jsonNumberFits<float>(json(std::nan(""))));
  EXPECT_FALSE(jsonNumberFits<int>(json("3")));
  EXPECT_FALSE(jsonNumberFits<int>(json(true)));
  EXPECT_EQ(jsonNumber<int>(json(7.0), "k"), 7);
  EXPECT_NE(errorOf([] { jsonNumber<int>(json(1e20), "k"); }).find("k must be an integer from -2147483648 to 2147483647"),
            std::string::npos);
}

TEST(SceneErrors, BadRenderOptionsAreRejected) {
  StereoRig rig = defaultRig();
  auto check = [&](const std::function<void(RenderOptions&, StereoRig&)>& mutate, const std::string& expected) {
    RenderOptions o;
    StereoRig r = rig;
    mutate(o, r);
    std::string message = errorOf([&] { validateOptions(o, r); });
    EXPECT_NE(message.find(expected), std::string::npos) << "got: '" << message << "'";
  };
  check([](RenderOptions& o, StereoRig&) { o.photonsX = 0; }, "photons must be positive");
  check([](RenderOptions& o, StereoRig&) { o.gather.density.radius = 0; }, "radius");
  check([](RenderOptions& o, StereoRig&) { o.gather.density.radius = -1; }, "radius");
  check([](RenderOptions& o, StereoRig&) { o.gather.density.radius = NAN; }, "radius");
  check([](RenderOptions& o, StereoRig&) { o.gather.density.radius = INFINITY; }, "radius");
  check([](RenderOptions& o, StereoRig&) { o.gather.density.estimator = Estimator::Knn, o.gather.density.k = 65; }, "k must");
  check([](RenderOptions&, StereoRig& r) { r.width = 0; }, "eye size");
  check([](RenderOptions&, StereoRig& r) { r.height = 100000; }, "eye size");
  check([](RenderOptions&, StereoRig& r) { r.ipd = NAN; }, "IPD");
}

}  // namespace
}  // namespace pvr
