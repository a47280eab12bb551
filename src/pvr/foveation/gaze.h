#pragma once
// Where the eyes look travels from a trajectory or a runtime, through a frame request, into the
// renderer's foveation options: every carrier has `float gaze[2][2]` (per eye, image fractions)
// and `bool verge` (the right eye fixates what the left eye's gaze meets).
#include <algorithm>

namespace pvr {

template <class To, class From>
void copyGaze(const From& from, To& to) {
  std::copy(&from.gaze[0][0], &from.gaze[0][0] + 4, &to.gaze[0][0]);
  to.verge = from.verge;
}

}  // namespace pvr
