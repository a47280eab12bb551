#include "pvr/stereo/vergence.h"

#include <algorithm>

namespace pvr {

void gazePixelOf(const float gaze[2], int width, int height, int& x, int& y) {
  x = std::min(width - 1, std::max(0, int(gaze[0] * float(width))));
  y = std::min(height - 1, std::max(0, int(gaze[1] * float(height))));
}

void vergeRightGaze(const StereoRig& rig, const float leftGaze[2], const float* leftInverseDepthAtGaze,
                    float rightGaze[2]) {
  rightGaze[0] = leftGaze[0], rightGaze[1] = leftGaze[1];
  if (!leftInverseDepthAtGaze) return;
  int gx, gy;
  gazePixelOf(leftGaze, rig.width, rig.height, gx, gy);
  const EyeCamera left = rig.eye(Eye::Left), right = rig.eye(Eye::Right);
  const float cx = float(gx) + 0.5f, cy = float(gy) + 0.5f, w = *leftInverseDepthAtGaze;
  float px, py;
  bool seen = w > 0.0f ? right.project(left.pointAt(cx, cy, w), px, py)
                       : right.projectDirection(left.pose.toWorldDir(left.localDirection(cx, cy)), px, py);
  if (!seen) return;
  rightGaze[0] = std::clamp(px / float(rig.width), 0.0f, 1.0f);
  rightGaze[1] = std::clamp(py / float(rig.height), 0.0f, 1.0f);
}

}  // namespace pvr
