#pragma once
// The CUDA backend: the frame pipeline of the CPU backend on the GPU (photon tracing, hash-grid
// or kd-tree build, the paper's single / hybrid / shared-memory eye passes, our cell-sorted
// pass), with CUDA-event stage timings. No CUDA header is needed to use it.
#include <memory>
#include <string>
#include <vector>

#include "pvr/accel/bvh.h"
#include "pvr/frame/frame.h"
#include "pvr/photon/photon_trace.h"

namespace pvr {

class Scene;

// True if a CUDA GPU can be used; otherwise `why` says why not in one line.
bool cudaDeviceUsable(std::string* why);

struct GpuRayThroughput {
  uint64_t primaryRays = 0, shadowRays = 0, diffuseRays = 0;
  double primaryMs = 0, shadowMs = 0, diffuseMs = 0;
  std::vector<Hit> leftPrimaryHits;  ///< pixel-centre hits of the left eye, row-major
};

struct GpuHashGridCopy {
  std::vector<Photon> photons;
  std::vector<uint32_t> cellStart, sortedToInput;
};

class CudaFrameRenderer : public FrameRenderer {
 public:
  explicit CudaFrameRenderer(const Scene& scene);
  ~CudaFrameRenderer() override;
  FrameResult render(const StereoRig& rig, const RenderOptions& options, bool images = true) override;
  void resetHistory() override;
  std::string name() const override { return "cuda"; }
  std::string deviceName() const override;

  // Pieces of the pipeline, for tests and benchmarks.
  std::vector<Photon> tracePhotons(const PhotonTraceParams& params);
  // Builds the hash grid over `photons` on the GPU `repeats` times; returns the median build time
  // in ms (CUDA events, cell keys to gathered photons; the photons' bounds are given, as the
  // tracer reduces them while tracing) and optionally the grid.
  double buildHashGrid(const std::vector<Photon>& photons, float radius, int repeats, GpuHashGridCopy* copy = nullptr);
  GpuRayThroughput measureRays(const StereoRig& rig, int repeats);
  const BvhBuildStats& bvhStats() const;
  size_t deviceBytes() const;  ///< GPU memory held by this backend now

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pvr
