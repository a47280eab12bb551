#pragma once
// The denoise stage on the GPU: each eye's history and a kernel per pass of the shared per-pixel
// code (pvr/denoise/svgf.h). The accumulation runs over every pixel and lists those the eye
// filters; the variance and a-trous passes run over that list only.
#include "pvr/cuda/cuda_util.cuh"
#include "pvr/denoise/denoise_eye_state.h"

namespace pvr::cuda {

class GpuDenoiser {
 public:
  // Denoises one eye's frame (device pointers, the eye's size) into image(eye), which the history
  // then follows. A history of another size starts again. The right eye under stereo reuse
  // (in.reusedFrom) reads what the left eye's denoise of this frame kept (in.keepLevels).
  void denoise(Eye eye, const EyeCamera& camera, const DenoiseParams& params, const DenoiseInputs& in, int stillFrames,
               cudaStream_t stream);
  const Vec3* image(Eye eye) const { return eyes_[int(eye)].out.data(); }
  void forget(Eye eye) { eyes_[int(eye)].valid = false; }
  size_t memoryBytes() const;

 private:
  struct EyeState : DenoiseEyeState<DeviceBuffer> {
    DeviceBuffer<Vec3> out;
    DeviceBuffer<uint32_t> filteredPixels;  ///< the pixels the eye filters, in 16x16-tile order
    // Under quarter photon passes, the same split: even pixels (x and y even) and the others.
    DeviceBuffer<uint32_t> evenPixels, oddPixels;
  };
  EyeState eyes_[2];
  // Per eye: the lengths of filteredPixels, evenPixels and oddPixels.
  static constexpr int kLists = 3;
  DeviceBuffer<unsigned> filteredCount_;
};

}  // namespace pvr::cuda
