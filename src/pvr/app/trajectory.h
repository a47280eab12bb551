#pragma once
// A recorded or scripted sequence of head poses and gaze points, one rendered frame per entry.
//
// Text file, one frame per line, whitespace-separated numbers, '#' starts a comment:
//   px py pz  qx qy qz qw  gx gy            (head position, orientation quaternion, gaze of both eyes)
//   px py pz  qx qy qz qw  lx ly  rx ry     (a gaze per eye)
// Position in scene units; the quaternion is OpenXR's XrQuaternionf order (x, y, z, w) and is
// normalized on reading; gaze points are image fractions in [0, 1] (0.5 0.5 = image centre).
#include <string>
#include <vector>

#include "pvr/camera/stereo_rig.h"

namespace pvr {

struct TrajectoryFrame {
  Pose head;
  float gaze[2][2] = {{0.5f, 0.5f}, {0.5f, 0.5f}};
  bool verge = true;  ///< one gaze on the line: the right eye fixates what the left eye does
};

// Throws pvr::Error naming the file and line for anything malformed (wrong count of numbers,
// non-numbers, non-finite values, a zero quaternion, gaze outside [0, 1]) or an empty file.
std::vector<TrajectoryFrame> loadTrajectory(const std::string& path);

}  // namespace pvr
