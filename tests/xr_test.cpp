// OpenXR without a runtime: the views <-> stereo rig conversion (round trips, canted displays,
// OpenXR's projection convention) and the session life cycle driven by recorded event sequences.
#include <gtest/gtest.h>

#include <cmath>

#include "pvr/xr/session_lifecycle.h"
#include "pvr/xr/xr_views.h"

namespace pvr {
namespace {

void expectNear(Vec3 a, Vec3 b, float tolerance) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

// The same rays through every corner and the centre of both eyes.
void expectSameEyes(const StereoRig& a, const StereoRig& b, float tolerance) {
  for (int e = 0; e < 2; ++e) {
    EyeCamera ca = a.eye(Eye(e)), cb = b.eye(Eye(e));
    for (float fx : {0.0f, 0.5f, 1.0f})
      for (float fy : {0.0f, 0.5f, 1.0f}) {
        Ray ra = ca.generateRay(fx * ca.width, fy * ca.height), rb = cb.generateRay(fx * cb.width, fy * cb.height);
        expectNear(ra.origin, rb.origin, tolerance);
        expectNear(ra.dir, rb.dir, tolerance);
      }
  }
}

Pose somePose() {
  Pose p;
  p.orientation = Quat::fromAxisAngle({0.3f, 1.0f, -0.2f}, 0.7f);
  p.position = {0.4f, 1.6f, -2.0f};
  return p;
}

TEST(XrViews, RigRoundTripsThroughViews) {
  StereoRig rig = defaultRig();
  rig.head = somePose();
  rig.width = 640, rig.height = 720;
  Pose sceneFromSpace;
  sceneFromSpace.orientation = Quat::fromAxisAngle({0, 1, 0}, 2.0f);
  sceneFromSpace.position = {1.0f, 0.0f, 3.0f};
  XrView views[2];
  viewsFromRig(rig, sceneFromSpace, views);
  StereoRig back = rigFromViews(views, sceneFromSpace, rig.width, rig.height);
  EXPECT_NEAR(back.ipd, rig.ipd, 1e-6f);
  expectNear(back.head.position, rig.head.position, 1e-5f);
  for (int e = 0; e < 2; ++e) {
    EXPECT_EQ(back.fov[e].angleLeft, rig.fov[e].angleLeft);
    EXPECT_EQ(back.fov[e].angleDown, rig.fov[e].angleDown);
    EXPECT_NEAR(std::fabs(back.eyeRotation[e].w), 1.0f, 1e-5f);  // parallel views: no per-eye turn
  }
  expectSameEyes(rig, back, 2e-5f);
}

TEST(XrViews, CantedDisplaysKeepEachEyesOrientation) {
  // Views turned outwards by 10 degrees each (as Pimax-style headsets report).
  XrView views[2] = {{XR_TYPE_VIEW}, {XR_TYPE_VIEW}};
  const float outward[2] = {0.1745f, -0.1745f};
  for (int e = 0; e < 2; ++e) {
    Pose eye;
    eye.orientation = Quat::fromAxisAngle({0, 1, 0}, outward[e]);
    eye.position = {e == 0 ? -0.032f : 0.032f, 1.7f, 0.0f};
    views[e].pose = poseToXr(eye);
    views[e].fov = {-0.9f, 0.7f, 0.8f, -0.85f};
  }
  StereoRig rig = rigFromViews(views, Pose(), 100, 120);
  EXPECT_NEAR(rig.ipd, 0.064f, 1e-6f);
  for (int e = 0; e < 2; ++e) {
    EyeCamera cam = rig.eye(Eye(e));
    expectNear(cam.pose.position, poseFromXr(views[e].pose).position, 1e-6f);
    expectNear(cam.pose.toWorldDir({0, 0, -1}), poseFromXr(views[e].pose).toWorldDir({0, 0, -1}), 1e-6f);
    expectNear(cam.pose.toWorldDir({0, 1, 0}), poseFromXr(views[e].pose).toWorldDir({0, 1, 0}), 1e-6f);
  }
  XrView again[2];
  viewsFromRig(rig, Pose(), again);
  for (int e = 0; e < 2; ++e) {
    expectNear(poseFromXr(again[e].pose).position, poseFromXr(views[e].pose).position, 1e-6f);
    expectNear(poseFromXr(again[e].pose).toWorldDir({1, 0, 0}), poseFromXr(views[e].pose).toWorldDir({1, 0, 0}), 1e-6f);
  }
}

// OpenXR's projection (the SDK's tangent-angle frustum, Vulkan's y-down clip space) sends a
// point to the same pixel as the rig's camera.
TEST(XrViews, PixelsMatchOpenXrProjection) {
  XrView views[2];
  StereoRig rig = defaultRig();
  rig.head = somePose();
  rig.width = 1440, rig.height = 1600;
  viewsFromRig(rig, Pose(), views);
  Vec3 points[] = {{0.1f, 1.5f, -3.0f}, {-0.7f, 2.2f, -2.5f}, {0.9f, 1.0f, -4.0f}};
  for (int e = 0; e < 2; ++e) {
    EyeCamera cam = rig.eye(Eye(e));
    Pose eyePose = poseFromXr(views[e].pose);
    const XrFovf& f = views[e].fov;
    float tl = std::tan(f.angleLeft), tr = std::tan(f.angleRight), tu = std::tan(f.angleUp), td = std::tan(f.angleDown);
    for (Vec3 p : points) {
      Vec3 v = eyePose.toLocalPoint(rig.head.toWorldPoint(p));
      float ndcX = (2.0f * (v.x / -v.z) - (tr + tl)) / (tr - tl);
      float ndcY = -(2.0f * (v.y / -v.z) - (tu + td)) / (tu - td);  // Vulkan: +y down
      float px = 0, py = 0;
      ASSERT_TRUE(cam.project(rig.head.toWorldPoint(p), px, py));
      EXPECT_NEAR(px, (ndcX + 1.0f) * 0.5f * rig.width, 2e-2f);
      EXPECT_NEAR(py, (ndcY + 1.0f) * 0.5f * rig.height, 2e-2f);
    }
  }
}

TEST(XrViews, RotationBetweenTurnsOneVectorOntoAnother) {
  Vec3 pairs[][2] = {{{1, 0, 0}, {0, 1, 0}}, {{1, 0, 0}, {1, 0, 0}}, {{1, 0, 0}, {-1, 0, 0}}, {{0, 0, 1}, normalize(Vec3(1, 2, 3))}};
  for (auto& p : pairs) expectNear(rotationBetween(p[0], p[1]).rotate(p[0]), p[1], 1e-6f);
}

std::vector<SessionCommand> feed(SessionLifecycle& life, std::initializer_list<XrSessionState> states) {
  std::vector<SessionCommand> out;
  for (XrSessionState s : states) out.push_back(life.onStateChanged(s));
  return out;
}

using C = SessionCommand;

TEST(SessionLifecycle, NormalRunEndedByTheApplication) {
  SessionLifecycle life;
  EXPECT_EQ(feed(life, {XR_SESSION_STATE_IDLE, XR_SESSION_STATE_READY}), (std::vector<C>{C::None, C::BeginSession}));
  EXPECT_TRUE(life.running());
  feed(life, {XR_SESSION_STATE_SYNCHRONIZED, XR_SESSION_STATE_VISIBLE, XR_SESSION_STATE_FOCUSED});
  EXPECT_TRUE(life.focused());
  EXPECT_EQ(life.requestStop(), C::RequestExit);
  EXPECT_EQ(life.requestStop(), C::None);  // asked once
  EXPECT_TRUE(life.running());             // frames stay due until the runtime stops the session
  EXPECT_EQ(feed(life, {XR_SESSION_STATE_VISIBLE, XR_SESSION_STATE_SYNCHRONIZED, XR_SESSION_STATE_STOPPING}),
            (std::vector<C>{C::None, C::None, C::EndSession}));
  EXPECT_FALSE(life.running());
  EXPECT_FALSE(life.finished());
  EXPECT_EQ(feed(life, {XR_SESSION_STATE_IDLE, XR_SESSION_STATE_EXITING}), (std::vector<C>{C::None, C::Shutdown}));
  EXPECT_TRUE(life.finished());
  EXPECT_FALSE(life.lost());
  EXPECT_EQ(life.focusChanges(), 2);
}

TEST(SessionLifecycle, RuntimeStopsAndRestartsTheSession) {  // headset taken off and put on again
  SessionLifecycle life;
  feed(life, {XR_SESSION_STATE_IDLE, XR_SESSION_STATE_READY, XR_SESSION_STATE_SYNCHRONIZED, XR_SESSION_STATE_VISIBLE});
  EXPECT_EQ(feed(life, {XR_SESSION_STATE_SYNCHRONIZED, XR_SESSION_STATE_STOPPING, XR_SESSION_STATE_IDLE}),
            (std::vector<C>{C::None, C::EndSession, C::None}));
  EXPECT_FALSE(life.finished());
  EXPECT_EQ(life.onStateChanged(XR_SESSION_STATE_READY), C::BeginSession);
  EXPECT_EQ(life.sessionsBegun(), 2);
}

TEST(SessionLifecycle, LossPendingShutsDown) {
  SessionLifecycle life;
  feed(life, {XR_SESSION_STATE_IDLE, XR_SESSION_STATE_READY, XR_SESSION_STATE_FOCUSED});
  EXPECT_EQ(life.onStateChanged(XR_SESSION_STATE_LOSS_PENDING), C::Shutdown);
  EXPECT_TRUE(life.finished());
  EXPECT_TRUE(life.lost());
  EXPECT_FALSE(life.running());
  EXPECT_EQ(life.onStateChanged(XR_SESSION_STATE_EXITING), C::None);  // nothing after the end
}

TEST(SessionLifecycle, InstanceLossShutsDown) {
  SessionLifecycle life;
  feed(life, {XR_SESSION_STATE_IDLE, XR_SESSION_STATE_READY});
  EXPECT_EQ(life.onInstanceLossPending(), C::Shutdown);
  EXPECT_TRUE(life.lost());
}

TEST(SessionLifecycle, StopBeforeTheSessionBegan) {
  SessionLifecycle life;
  life.onStateChanged(XR_SESSION_STATE_IDLE);
  EXPECT_EQ(life.requestStop(), C::Shutdown);
  EXPECT_TRUE(life.finished());
  EXPECT_EQ(life.onStateChanged(XR_SESSION_STATE_READY), C::None);  // never begun
  EXPECT_EQ(life.sessionsBegun(), 0);
}

TEST(SessionLifecycle, StopWhileStoppedByTheRuntime) {
  SessionLifecycle life;
  feed(life, {XR_SESSION_STATE_IDLE, XR_SESSION_STATE_READY, XR_SESSION_STATE_STOPPING, XR_SESSION_STATE_IDLE});
  EXPECT_EQ(life.requestStop(), C::Shutdown);  // not running: nothing to walk down
  EXPECT_TRUE(life.finished());
}

}  // namespace
}  // namespace pvr
