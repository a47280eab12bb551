#pragma once
// The denoise stage on the GPU: each eye's history and a kernel per pass of the shared per-pixel
// code (pvr/denoise/svgf.h).
#include "pvr/cuda/cuda_util.cuh"
#include "pvr/denoise/svgf.h"

namespace pvr::cuda {

class GpuDenoiser {
 public:
  // Denoises one eye's frame (device pointers, the eye's size) into image(eye), which the history
  // then follows. A history of another size starts again.
  void denoise(Eye eye, const EyeCamera& camera, const DenoiseParams& params, const DenoiseInputs& in, int stillFrames,
               cudaStream_t stream);
  const Vec3* image(Eye eye) const { return eyes_[int(eye)].out.data(); }
  // Per eye, the pixels of the last denoise that took history, copied when the stream gets there.
  void downloadHistoryPixels(unsigned host[2], cudaStream_t stream) const;
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
    bool valid = false;
    EyeCamera camera;
    DeviceBuffer<Vec3> albedo, out;
    DeviceBuffer<float> depthGradient;
    DeviceBuffer<ColourVariance> accumulated[2], filtered[2][2];
  };
  EyeState eyes_[2];
  DeviceBuffer<unsigned> historyPixels_;
};

}  // namespace pvr::cuda
