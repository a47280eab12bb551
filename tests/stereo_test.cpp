// The stereo rig: pixel -> ray -> world point -> pixel round trips for both eyes with
// asymmetric fields of view and a rotated head, eye placement by IPD, and the FOV angles.
#include <gtest/gtest.h>

#include <random>

#include "pvr/camera/stereo_rig.h"

namespace pvr {
namespace {

StereoRig testRig() {
  StereoRig rig = defaultRig();
  const float deg = kPi / 180.0f;
  rig.fov[0] = {-52.0f * deg, 41.0f * deg, 48.0f * deg, -55.0f * deg};  // Index-like, asymmetric
  rig.fov[1] = {-41.0f * deg, 52.0f * deg, 47.0f * deg, -53.0f * deg};
  rig.width = 1440;
  rig.height = 1600;
  rig.head.position = {0.3f, 1.6f, -2.0f};
  rig.head.orientation = Quat::fromAxisAngle({0.3f, 1.0f, 0.2f}, 0.7f);
  return rig;
}

TEST(StereoRig, PixelRayWorldPixelRoundTrip) {
  StereoRig rig = testRig();
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(0, 1);
  for (Eye e : {Eye::Left, Eye::Right}) {
    EyeCamera cam = rig.eye(e);
    for (int i = 0; i < 2000; ++i) {
      float px = u(rng) * cam.width, py = u(rng) * cam.height, t = 0.1f + 20.0f * u(rng);
      Ray ray = cam.generateRay(px, py);
      ASSERT_NEAR(length(ray.dir), 1.0f, 1e-5f);
      Vec3 world = ray.origin + ray.dir * t;
      float qx, qy;
      ASSERT_TRUE(cam.project(world, qx, qy));
      ASSERT_NEAR(qx, px, 2e-3f);
      ASSERT_NEAR(qy, py, 2e-3f);
      ASSERT_TRUE(cam.containsPixel(qx, qy));
    }
  }
}

TEST(StereoRig, WorldPixelRayRoundTripAndBehindTheEye) {
  StereoRig rig = testRig();
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-3, 3);
  int projected = 0;
  for (Eye e : {Eye::Left, Eye::Right}) {
    EyeCamera cam = rig.eye(e);
    for (int i = 0; i < 2000; ++i) {
      Vec3 world = rig.head.position + Vec3(u(rng), u(rng), u(rng));
      float px, py;
      bool inFront = cam.pose.toLocalPoint(world).z < 0;
      ASSERT_EQ(cam.project(world, px, py), inFront);
      if (!inFront) continue;
      ++projected;
      Ray ray = cam.generateRay(px, py);  // must pass through the world point
      Vec3 toPoint = world - ray.origin;
      ASSERT_NEAR(length(cross(ray.dir, toPoint)) / length(toPoint), 0.0f, 1e-4f);
      ASSERT_GT(dot(ray.dir, toPoint), 0.0f);
    }
  }
  EXPECT_GT(projected, 1000);
}

TEST(StereoRig, EyesAreIpdApartAlongTheHeadsRightAxis) {
  StereoRig rig = testRig();
  rig.ipd = 0.063f;
  Vec3 l = rig.eye(Eye::Left).pose.position, r = rig.eye(Eye::Right).pose.position;
  EXPECT_NEAR(length(r - l), 0.063f, 1e-6f);
  Vec3 right = rig.head.orientation.rotate({1, 0, 0});
  EXPECT_NEAR(dot(normalize(r - l), right), 1.0f, 1e-5f);
  EXPECT_NEAR(length((l + r) * 0.5f - rig.head.position), 0.0f, 1e-6f);
}

TEST(StereoRig, ImageEdgesAreTheFovAngles) {
  StereoRig rig = testRig();
  rig.head.orientation = Quat{};
  EyeCamera cam = rig.eye(Eye::Left);
  auto angle = [](Vec3 d, int axis) { return std::atan2(d[axis], -d.z); };
  EXPECT_NEAR(angle(cam.generateRay(0, cam.height * 0.5f).dir, 0), cam.fov.angleLeft, 1e-5f);
  EXPECT_NEAR(angle(cam.generateRay(float(cam.width), cam.height * 0.5f).dir, 0), cam.fov.angleRight, 1e-5f);
  // Pixel row 0 is the top of the image.
  float x0 = cam.width * (-std::tan(cam.fov.angleLeft)) / (std::tan(cam.fov.angleRight) - std::tan(cam.fov.angleLeft));
  EXPECT_NEAR(angle(cam.generateRay(x0, 0).dir, 1), cam.fov.angleUp, 1e-5f);
  EXPECT_NEAR(angle(cam.generateRay(x0, float(cam.height)).dir, 1), cam.fov.angleDown, 1e-5f);
}

TEST(StereoRig, LookAtLooksAtTheTarget) {
  Vec3 from{1, 2, 3}, target{-2, 0.5f, -4};
  Quat q = lookAtOrientation(from, target);
  EXPECT_NEAR(dot(q.rotate({0, 0, -1}), normalize(target - from)), 1.0f, 1e-5f);
  EXPECT_NEAR(q.rotate({1, 0, 0}).y, 0.0f, 1e-5f) << "no roll";
}

}  // namespace
}  // namespace pvr
