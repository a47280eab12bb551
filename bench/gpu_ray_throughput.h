#pragma once
// Rays per second through the CUDA traversal, both eyes' pixels: primary rays, shadow rays to a
// light sample from each primary hit, and cosine-distributed diffuse rays from each primary hit
// (the rays suite of `photonvr bench`). No CUDA header is needed to use it.
#include <cstdint>
#include <vector>

#include "pvr/cuda/cuda_frame_backend.h"

namespace pvr {

struct GpuRayThroughput {
  uint64_t primaryRays = 0, shadowRays = 0, diffuseRays = 0;
  double primaryMs = 0, shadowMs = 0, diffuseMs = 0;  ///< medians over the repeats
  std::vector<Hit> leftPrimaryHits;                    ///< pixel-centre hits of the left eye, row-major
};

GpuRayThroughput measureGpuRays(CudaFrameBackend& backend, const StereoRig& rig, int repeats);

}  // namespace pvr
