#pragma once
// Per-eye pinhole cameras of a headset: head pose, interpupillary distance, asymmetric field of
// view (OpenXR's XrFovf: four signed angles) and per-eye resolution. World-to-pixel and
// pixel-to-ray are exact inverses; the main paper's equations 3-5 are the symmetric special case.
#include "pvr/geometry/ray.h"
#include "pvr/math/vec.h"

namespace pvr {

// Rigid transform from a local frame to world space (OpenXR's XrPosef).
struct Pose {
  Quat orientation;
  Vec3 position;
  PVR_HOST_DEVICE Vec3 toWorldPoint(Vec3 p) const { return orientation.rotate(p) + position; }
  PVR_HOST_DEVICE Vec3 toWorldDir(Vec3 d) const { return orientation.rotate(d); }
  PVR_HOST_DEVICE Vec3 toLocalPoint(Vec3 p) const { return orientation.conjugate().rotate(p - position); }
};

// Field of view as four angles in radians: left and down are negative for a view that contains
// the optical axis, as in XrFovf.
struct Fov {
  float angleLeft = -0.8f, angleRight = 0.8f, angleUp = 0.8f, angleDown = -0.8f;
};

enum class Eye : int { Left = 0, Right = 1 };

// One eye: a pinhole at pose.position looking down its local -Z, Y up, pixel (0,0) top-left.
struct EyeCamera {
  Pose pose;
  Fov fov;
  int width = 1440, height = 1600;

  // Image-plane coordinates at z = -1 of the pixel-space point (px, py) (continuous, 0..width).
  PVR_HOST_DEVICE Vec3 localDirection(float px, float py) const {
    float tl = tanf(fov.angleLeft), tr = tanf(fov.angleRight);
    float tu = tanf(fov.angleUp), td = tanf(fov.angleDown);
    float x = tl + (px / float(width)) * (tr - tl);
    float y = tu - (py / float(height)) * (tu - td);
    return {x, y, -1.0f};
  }

  // Primary ray through the continuous pixel position (px, py); the direction is normalized.
  PVR_HOST_DEVICE Ray generateRay(float px, float py) const {
    return {pose.position, normalize(pose.toWorldDir(localDirection(px, py)))};
  }

  // Continuous pixel position of a world point; returns false if the point is behind the eye.
  // The pixel may lie outside [0,width)x[0,height): callers check containsPixel.
  PVR_HOST_DEVICE bool project(Vec3 world, float& px, float& py) const {
    return projectLocal(pose.toLocalPoint(world), px, py);
  }
  // Continuous pixel position of the point at infinity in direction `worldDir`.
  PVR_HOST_DEVICE bool projectDirection(Vec3 worldDir, float& px, float& py) const {
    return projectLocal(pose.orientation.conjugate().rotate(worldDir), px, py);
  }

  // 1 / z of a world point, z its distance along the view axis; 0 for points not in front.
  // Inverse depth is affine in pixel space across a plane, so it interpolates exactly.
  PVR_HOST_DEVICE float inverseDepthOf(Vec3 world) const {
    float z = -pose.toLocalPoint(world).z;
    return z > 0.0f ? 1.0f / z : 0.0f;
  }
  // The world point seen through pixel-space (px, py) at inverse depth w > 0.
  PVR_HOST_DEVICE Vec3 pointAt(float px, float py, float inverseDepth) const {
    return pose.toWorldPoint(localDirection(px, py) * (1.0f / inverseDepth));
  }

  // The width of one pixel's footprint per unit distance along the view axis (a ray cone's
  // spread for texture filtering).
  PVR_HOST_DEVICE float pixelSpread() const { return (tanf(fov.angleUp) - tanf(fov.angleDown)) / float(height); }

  PVR_HOST_DEVICE bool containsPixel(float px, float py) const {
    return px >= 0.0f && py >= 0.0f && px < float(width) && py < float(height);
  }

 private:
  PVR_HOST_DEVICE bool projectLocal(Vec3 v, float& px, float& py) const {
    if (!(v.z < 0.0f)) return false;
    float x = v.x / -v.z, y = v.y / -v.z;
    float tl = tanf(fov.angleLeft), tr = tanf(fov.angleRight);
    float tu = tanf(fov.angleUp), td = tanf(fov.angleDown);
    px = (x - tl) / (tr - tl) * float(width);
    py = (tu - y) / (tu - td) * float(height);
    return true;
  }
};

// Head pose + IPD + per-eye FOV and resolution. Eyes sit at -/+ ipd/2 along the head's local X.
// Each eye may be turned relative to the head (canted displays report per-view orientations);
// both are the identity for parallel views.
struct StereoRig {
  Pose head;
  float ipd = 0.063f;
  Fov fov[2];
  int width = 1440, height = 1600;
  Quat eyeRotation[2];

  PVR_HOST_DEVICE EyeCamera eye(Eye e) const {
    float side = e == Eye::Left ? -0.5f : 0.5f;
    EyeCamera cam;
    cam.pose.orientation = head.orientation * eyeRotation[int(e)];
    cam.pose.position = head.toWorldPoint({side * ipd, 0.0f, 0.0f});
    cam.fov = fov[int(e)];
    cam.width = width;
    cam.height = height;
    return cam;
  }
};

// A headset-like default: about 104 x 112 degrees per eye, each eye's view extending further
// outwards (temporal) than inwards (nasal), as real HMD projections do.
inline StereoRig defaultRig() {
  StereoRig rig;
  const float deg = kPi / 180.0f;
  rig.fov[0] = {-54.0f * deg, 50.0f * deg, 56.0f * deg, -56.0f * deg};
  rig.fov[1] = {-50.0f * deg, 54.0f * deg, 56.0f * deg, -56.0f * deg};
  return rig;
}

// Orientation that looks from `from` towards `target` with +Y as up.
inline Quat lookAtOrientation(Vec3 from, Vec3 target, Vec3 up = {0, 1, 0}) {
  Vec3 back = normalize(from - target);  // local +Z
  Vec3 right = normalize(cross(up, back));
  Vec3 newUp = cross(back, right);
  // Rotation matrix columns (right, newUp, back) -> quaternion.
  float m00 = right.x, m01 = newUp.x, m02 = back.x;
  float m10 = right.y, m11 = newUp.y, m12 = back.y;
  float m20 = right.z, m21 = newUp.z, m22 = back.z;
  float trace = m00 + m11 + m22;
  Quat q;
  if (trace > 0) {
    float s = sqrtf(trace + 1.0f) * 2.0f;
    q = {(m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, 0.25f * s};
  } else if (m00 > m11 && m00 > m22) {
    float s = sqrtf(1.0f + m00 - m11 - m22) * 2.0f;
    q = {0.25f * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s};
  } else if (m11 > m22) {
    float s = sqrtf(1.0f + m11 - m00 - m22) * 2.0f;
    q = {(m01 + m10) / s, 0.25f * s, (m12 + m21) / s, (m02 - m20) / s};
  } else {
    float s = sqrtf(1.0f + m22 - m00 - m11) * 2.0f;
    q = {(m02 + m20) / s, (m12 + m21) / s, 0.25f * s, (m10 - m01) / s};
  }
  return q;
}

}  // namespace pvr
