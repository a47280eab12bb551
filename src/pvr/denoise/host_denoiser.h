#pragma once
// The denoise stage on the host (the CPU backend's): each eye's history and the passes of
// svgf.h over its pixels, in parallel rows.
#include <vector>

#include "pvr/denoise/svgf.h"
#include "pvr/image/image.h"

namespace pvr {

class HostDenoiser {
 public:
  // Denoises one eye's frame (inputs the eye's size) into `out`, which the history then follows;
  // `stillFrames` > 0 refines (DenoiseParams). Returns the number of pixels that took history. A
  // history of another size starts again.
  size_t denoise(Eye eye, const EyeCamera& camera, const DenoiseParams& params, const DenoiseInputs& in, Image& out,
                 int stillFrames = 0);
  void forget(Eye eye) { eyes_[int(eye)].valid = false; }

 private:
  // What one frame leaves for the next.
  struct History {
    std::vector<ColourVariance> colour[2];
    std::vector<float> moments, length;
    std::vector<DenoiseGuide> guide;
  };
  struct EyeState {
    History history[2];  ///< ping-pong: the last frame's, and the one being written
    int latest = 0, signals = 0;
    bool valid = false;
    EyeCamera camera;
    std::vector<float> depthGradient;
    std::vector<ColourVariance> levels[2][kDenoiseLevels];  ///< two (ping-pong) unless keepLevels
    int keptLevels = 0;  ///< levels of this frame kept apart for the right eye (keepLevels)
  };
  EyeState eyes_[2];
};

}  // namespace pvr
