#pragma once
// The denoise stage on the GPU: each eye's history and a kernel per pass of the shared per-pixel
// code (pvr/denoise/svgf.h). The accumulation runs over every pixel and lists those the eye
// filters; the variance and a-trous passes run over that list only.
#include "pvr/cuda/cuda_util.cuh"
#include "pvr/denoise/svgf.h"

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
  struct History {
    DeviceBuffer<ColourVariance> colour[2];
    DeviceBuffer<float> moments, length;
    DeviceBuffer<DenoiseGuide> guide;
    size_t bytes() const { return colour[0].bytes() + colour[1].bytes() + moments.bytes() + length.bytes() + guide.bytes(); }
  };
  struct EyeState {
    History history[2];
    int latest = 0, signals = 0;
    int keptLevels = 0;  ///< levels of this frame kept apart for the right eye (keepLevels)
    bool valid = false;
    EyeCamera camera;
    DeviceBuffer<Vec3> out;
    DeviceBuffer<float> depthGradient;
    DeviceBuffer<ColourVariance> levels[2][kDenoiseLevels];  ///< two (ping-pong) unless keepLevels
    DeviceBuffer<uint32_t> filteredPixels;                   ///< the pixels the eye filters, in warps of neighbours
  };
  EyeState eyes_[2];
  DeviceBuffer<unsigned> filteredCount_;  ///< per eye, the length of filteredPixels
};

}  // namespace pvr::cuda
