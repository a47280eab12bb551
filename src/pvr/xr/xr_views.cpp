#include "pvr/xr/xr_views.h"

#include <cmath>

namespace pvr {
namespace {

Quat normalized(Quat q) {
  float n = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  return n > 0 ? Quat{q.x / n, q.y / n, q.z / n, q.w / n} : Quat{};
}

}  // namespace

Pose composePoses(const Pose& a, const Pose& b) {
  return {normalized(a.orientation * b.orientation), a.toWorldPoint(b.position)};
}

Pose inversePose(const Pose& p) {
  Quat inv = p.orientation.conjugate();
  return {inv, inv.rotate(p.position * -1.0f)};
}

Quat rotationBetween(Vec3 a, Vec3 b) {
  float d = dot(a, b);
  if (d < -0.999999f) {  // opposite: half a turn about any axis perpendicular to a
    Vec3 axis = cross(Vec3(1, 0, 0), a);
    if (length(axis) < 1e-3f) axis = cross(Vec3(0, 1, 0), a);
    return Quat::fromAxisAngle(axis, kPi);
  }
  Vec3 c = cross(a, b);
  return normalized({c.x, c.y, c.z, 1.0f + d});
}

StereoRig rigFromViews(const XrView views[2], const Pose& sceneFromSpace, int width, int height) {
  Pose eye[2];
  for (int e = 0; e < 2; ++e) eye[e] = composePoses(sceneFromSpace, poseFromXr(views[e].pose));
  StereoRig rig;
  rig.width = width, rig.height = height;
  Vec3 baseline = eye[1].position - eye[0].position;
  rig.ipd = length(baseline);
  Quat head = eye[0].orientation;
  if (rig.ipd > 1e-7f) {  // turn the left eye's frame so that its X runs along the baseline
    Vec3 x = head.rotate({1, 0, 0});
    head = normalized(rotationBetween(x, baseline * (1.0f / rig.ipd)) * head);
  }
  rig.head.orientation = head;
  rig.head.position = (eye[0].position + eye[1].position) * 0.5f;
  for (int e = 0; e < 2; ++e) {
    rig.eyeRotation[e] = normalized(head.conjugate() * eye[e].orientation);
    const XrFovf& f = views[e].fov;
    rig.fov[e] = {f.angleLeft, f.angleRight, f.angleUp, f.angleDown};
  }
  return rig;
}

void viewsFromRig(const StereoRig& rig, const Pose& sceneFromSpace, XrView views[2]) {
  Pose spaceFromScene = inversePose(sceneFromSpace);
  for (int e = 0; e < 2; ++e) {
    EyeCamera cam = rig.eye(Eye(e));
    views[e] = {XR_TYPE_VIEW};
    views[e].pose = poseToXr(composePoses(spaceFromScene, cam.pose));
    views[e].fov = {cam.fov.angleLeft, cam.fov.angleRight, cam.fov.angleUp, cam.fov.angleDown};
  }
}

}  // namespace pvr
