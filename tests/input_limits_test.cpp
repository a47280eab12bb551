// The input limits (pvr/util/input_limits.h): each is refused with a line that names the limit.
// The limits are lowered here so that inputs just past them are small.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "pvr/app/trajectory.h"
#include "pvr/scene/scene.h"
#include "pvr/util/error.h"
#include "pvr/util/input_limits.h"

namespace pvr {
namespace {

// Sets limits for one test and restores the defaults after it.
class InputLimitsTest : public ::testing::Test {
 protected:
  void TearDown() override { setInputLimits(InputLimits()); }
};

// The message of what `f` throws (empty if it does not throw pvr::Error).
template <class F>
std::string errorOf(F f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// n separate triangles in the xy plane.
void addTriangles(Scene& scene, uint32_t material, int n) {
  std::vector<Vec3> v;
  std::vector<uint32_t> idx;
  for (int i = 0; i < n; ++i) {
    v.insert(v.end(), {Vec3{float(i), 0, 0}, Vec3{float(i) + 1, 0, 0}, Vec3{float(i), 1, 0}});
    idx.insert(idx.end(), {uint32_t(3 * i), uint32_t(3 * i + 1), uint32_t(3 * i + 2)});
  }
  scene.addMesh("tris", v, {}, idx, material);
}

TEST_F(InputLimitsTest, TrianglesPastTheLimitAreRefused) {
  InputLimits l;
  l.triangles = 10;
  setInputLimits(l);
  Scene scene;
  const uint32_t m = scene.addMaterial(Material{}, "m");
  addTriangles(scene, m, 6);
  addTriangles(scene, m, 4);  // exactly at the limit
  EXPECT_EQ(scene.triangleCount(), 10u);
  EXPECT_EQ(errorOf([&] { addTriangles(scene, m, 1); }), "mesh 'tris' brings the scene to 11 triangles: at most 10");
}

TEST_F(InputLimitsTest, TexturesPastTheLimitsAreRefused) {
  InputLimits l;
  l.textures = 2;
  l.textureSide = 8;
  setInputLimits(l);
  Scene scene;
  auto add = [&](int w, int h) { scene.addTexture("t", w, h, std::vector<uint32_t>(size_t(w) * h, 0xff808080u), true); };
  add(8, 8);
  EXPECT_EQ(errorOf([&] { add(9, 1); }), "texture 't' is 9x1: at most 8 texels per side");
  EXPECT_EQ(errorOf([&] { add(1, 16); }), "texture 't' is 1x16: at most 8 texels per side");
  add(4, 4);
  EXPECT_EQ(errorOf([&] { add(2, 2); }), "texture 't': a scene has at most 2 textures");
  EXPECT_EQ(scene.textureCount(), 2u);

  l = InputLimits();
  l.textureBytes = 3 << 20;  // 3 MiB: one 512x512 texture (1.33 MiB with its levels) fits twice, not three times
  setInputLimits(l);
  Scene big;
  auto addBig = [&] { big.addTexture("big", 512, 512, std::vector<uint32_t>(512 * 512, 0xffffffffu), false); };
  addBig();
  addBig();
  const std::string e = errorOf(addBig);
  EXPECT_NE(e.find("texture 'big': the scene's textures would take"), std::string::npos) << e;
  EXPECT_NE(e.find("at most 3 MiB"), std::string::npos) << e;
}

TEST_F(InputLimitsTest, LongTrajectoriesAndLargeSceneFilesAreRefused) {
  const std::string dir = testing::TempDir();
  const std::string traj = dir + "/limit.traj";
  {
    std::ofstream out(traj);
    for (int i = 0; i < 4; ++i) out << "0 0 0 0 0 0 1 0.5 0.5\n";
  }
  InputLimits l;
  l.trajectoryFrames = 4;
  setInputLimits(l);
  EXPECT_EQ(loadTrajectory(traj).size(), 4u);
  l.trajectoryFrames = 3;
  setInputLimits(l);
  EXPECT_EQ(errorOf([&] { loadTrajectory(traj); }), "trajectory '" + traj + "' has more than 3 frames: at most 3");

  const std::string json = dir + "/limit.json";
  {
    std::ofstream out(json);
    out << "{\"base\": \"cornell\"" << std::string(size_t(2) << 20, ' ') << "}\n";
  }
  EXPECT_EQ(loadScene(json).name.empty(), false);  // 2 MiB: under the default limit
  l = InputLimits();
  l.sceneFileBytes = 1 << 20;
  setInputLimits(l);
  EXPECT_EQ(errorOf([&] { loadScene(json); }), "scene file '" + json + "' is 2 MiB: at most 1 MiB");
}

}  // namespace
}  // namespace pvr
