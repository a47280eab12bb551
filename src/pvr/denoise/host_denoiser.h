#pragma once
// The denoise stage on the host (the CPU backend's): each eye's history and the passes of
// svgf.h over its pixels, in parallel rows.
#include <vector>

#include "pvr/denoise/denoise_eye_state.h"
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
  // Tests: before each frame's passes, fill what they write (the next history's colours, moments
  // and lengths, the filter levels) with NaN, so that a read of anything this frame or the history's
  // frame did not write shows in the image (a fresh buffer's zeros would hide it; the GPU's memory
  // holds whatever it held).
  void poisonUnwritten(bool on) { poison_ = on; }

 private:
  template <class T>
  using HostBuffer = std::vector<T>;
  using EyeState = DenoiseEyeState<HostBuffer>;
  EyeState eyes_[2];
  bool poison_ = false;
};

}  // namespace pvr
