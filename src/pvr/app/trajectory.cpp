#include "pvr/app/trajectory.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "pvr/util/error.h"
#include "pvr/util/input_limits.h"

namespace pvr {

std::vector<TrajectoryFrame> loadTrajectory(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot open trajectory '" + path + "': no such file or not readable");
  std::vector<TrajectoryFrame> frames;
  std::string line;
  for (uint64_t lineNumber = 1; std::getline(in, line); ++lineNumber) {
    std::string where = "trajectory '" + path + "' line " + std::to_string(lineNumber);
    line = line.substr(0, line.find('#'));
    std::istringstream fields(line);
    std::vector<float> v;
    std::string token;
    while (fields >> token) {
      try {
        size_t used = 0;
        float f = std::stof(token, &used);
        if (used != token.size()) throw std::invalid_argument(token);
        v.push_back(f);
      } catch (const std::exception&) {
        throw Error(where + ": '" + token + "' is not a number");
      }
    }
    if (v.empty()) continue;
    if (v.size() != 9 && v.size() != 11)
      throw Error(where + ": expected 9 numbers (position, quaternion x y z w, gaze x y) or 11 (a gaze per eye), got " +
                  std::to_string(v.size()));
    for (float f : v)
      if (!std::isfinite(f)) throw Error(where + ": non-finite value");
    TrajectoryFrame frame;
    frame.head.position = {v[0], v[1], v[2]};
    float norm = std::sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
    if (!(norm > 1e-6f)) throw Error(where + ": the orientation quaternion is zero");
    frame.head.orientation = {v[3] / norm, v[4] / norm, v[5] / norm, v[6] / norm};
    for (int e = 0; e < 2; ++e)
      for (int k = 0; k < 2; ++k) {
        float g = v.size() == 9 ? v[7 + k] : v[7 + 2 * e + k];
        if (!(g >= 0.0f && g <= 1.0f)) throw Error(where + ": gaze coordinates must lie in [0, 1]");
        frame.gaze[e][k] = g;
      }
    frame.verge = v.size() == 9;
    if (frames.size() >= inputLimits().trajectoryFrames)
      throw Error("trajectory '" + path + "' has more than " + std::to_string(inputLimits().trajectoryFrames) +
                  " frames: at most " + std::to_string(inputLimits().trajectoryFrames));
    frames.push_back(frame);
  }
  if (frames.empty()) throw Error("trajectory '" + path + "' has no frames");
  return frames;
}

}  // namespace pvr
