#pragma once
// Rays per second through the CUDA traversal, both eyes' pixels: primary rays, shadow rays to a
// light sample from each primary hit, and cosine-distributed diffuse rays from each primary hit
// (the rays suite of `photonvr bench`). No CUDA header is needed to use it.
#include <cstdint>
#include <memory>
#include <vector>

#include "pvr/accel/wide_bvh.h"
#include "pvr/cuda/cuda_frame_backend.h"

namespace pvr {

struct GpuRayThroughput {
  uint64_t primaryRays = 0, shadowRays = 0, diffuseRays = 0;
  double primaryMs = 0, shadowMs = 0, diffuseMs = 0;  ///< medians over the repeats
  std::vector<Hit> leftPrimaryHits;                    ///< pixel-centre hits of the left eye, row-major
};

// The rays of one BVH layout, uploaded beside the backend's scene (whose shading data the shadow
// and diffuse rays use): the binary BVH and the 8-wide one side by side.
class GpuRayBench {
 public:
  GpuRayBench(CudaFrameBackend& backend, const Bvh& bvh);
  GpuRayBench(CudaFrameBackend& backend, const WideBvh& bvh);
  ~GpuRayBench();
  GpuRayBench(const GpuRayBench&) = delete;
  GpuRayBench& operator=(const GpuRayBench&) = delete;
  // sharedStack: the traversal stack in shared memory, as the renderer's kernels keep it; false:
  // in local memory (for comparison).
  GpuRayThroughput measure(const StereoRig& rig, int repeats, bool sharedStack = true);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The photon pass alone, as a frame runs it (CudaFrameBackend::tracePhotons: the paths, the scan
// of their counts and the compaction), timed with CUDA events over `repeats` runs after one
// warm-up run: each run's milliseconds. `stored` receives the photons the last run stored.
std::vector<double> timePhotonTrace(CudaFrameBackend& backend, const PhotonTraceParams& params, int repeats,
                                    size_t& stored);

}  // namespace pvr
