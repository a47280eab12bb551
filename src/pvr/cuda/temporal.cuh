#pragma once
// The temporal stage on the GPU: each eye's history (its last displayed image, depth and camera)
// and the resolve kernel over the shared per-pixel code (pvr/temporal/taa.h).
#include "pvr/cuda/cuda_util.cuh"
#include "pvr/temporal/taa.h"

namespace pvr::cuda {

class GpuTemporal {
 public:
  // Blends the eye's current image (with its depth, and sample spacing if foveated; device
  // pointers) with the eye's history into image(eye), which (less the emitted part, if given)
  // becomes the history. A history of another eye size, or none, leaves the image as rendered.
  void resolve(Eye eye, const EyeCamera& camera, const TaaParams& params, const Vec3* current, const float* inverseDepth,
               const float* sampleSpacing, const TaaEmitted& emission, cudaStream_t stream);
  const Vec3* image(Eye eye) const {
    return emittedApart_[int(eye)] ? displayed_[int(eye)].data() : colour_[int(eye)][latest_[int(eye)]].data();
  }
  // Per eye, the pixels of the last resolve that took history, copied when the stream gets there.
  void downloadHistoryPixels(unsigned host[2], cudaStream_t stream) const;
  void forget(Eye eye) { valid_[int(eye)] = false; }
  size_t memoryBytes() const;

 private:
  DeviceBuffer<Vec3> colour_[2][2];  ///< per eye, ping-pong: the history and the frame being resolved
  DeviceBuffer<Vec3> displayed_[2];  ///< per eye, the resolved frame with its emitted part, where that is kept apart
  bool emittedApart_[2] = {false, false};
  DeviceBuffer<float> depth_[2];
  DeviceBuffer<unsigned> historyPixels_;
  EyeCamera camera_[2];
  bool valid_[2] = {false, false};
  int latest_[2] = {0, 0};
};

}  // namespace pvr::cuda
