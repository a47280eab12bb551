#pragma once
// The eye images of a frame the loop hands to a presenter, as a hand-over's source: the CUDA
// backend's device buffers (with the stream that wrote them) or the host images.
#include "pvr/loop/presenter.h"
#include "pvr/vk/eye_transfer.h"

namespace pvr {

inline EyeSource eyeSourceOf(const PresentedFrame& frame, Eye eye) {
  EyeSource source;
  if (frame.onDevice) {
    source.deviceImage = frame.renderer.deviceImage(eye);
    source.deviceInverseDepth = frame.renderer.deviceInverseDepth(eye);
    source.deviceStream = frame.renderer.deviceStream();
  } else if (frame.result) {
    source.image = &frame.result->eyes[int(eye)].image;
    source.inverseDepth = &frame.result->eyes[int(eye)].inverseDepth;
  }
  return source;
}

}  // namespace pvr
