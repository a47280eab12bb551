#pragma once
// OpenXR's views and photonvr's stereo rig. The rig's conventions are OpenXR's (XrPosef: -Z
// forward, +Y up; XrFovf: four signed tangent angles; pixel (0,0) top-left as with Vulkan
// swapchains), so the conversion only regroups: the head sits between the eyes with its X axis
// along the baseline, and each eye keeps its own orientation (canted displays) as a rotation
// relative to the head.
#include <openxr/openxr.h>

#include "pvr/camera/stereo_rig.h"

namespace pvr {

inline Pose poseFromXr(const XrPosef& p) {
  return {{p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w}, {p.position.x, p.position.y, p.position.z}};
}
inline XrPosef poseToXr(const Pose& p) {
  XrPosef x;
  x.orientation = {p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w};
  x.position = {p.position.x, p.position.y, p.position.z};
  return x;
}
// a then b: the pose b expressed in a's parent frame (b is relative to a).
Pose composePoses(const Pose& a, const Pose& b);
Pose inversePose(const Pose& p);

// The rig of OpenXR's two views (located in a reference space), placed in the scene by
// `sceneFromSpace` (the reference space's origin in scene coordinates), at width x height per eye.
StereoRig rigFromViews(const XrView views[2], const Pose& sceneFromSpace, int width, int height);
// The inverse: the two views (in the reference space) whose rig is `rig`.
void viewsFromRig(const StereoRig& rig, const Pose& sceneFromSpace, XrView views[2]);

// The rotation taking unit vector a to unit vector b by the smallest angle.
Quat rotationBetween(Vec3 a, Vec3 b);

}  // namespace pvr
