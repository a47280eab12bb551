#pragma once
// The eye pass on the GPU: the paper's three kernel schemes over the shared gathering code,
// and the ray-throughput kernels of the benchmark.
#include <memory>
#include <vector>

#include "pvr/cuda/gpu_scene.cuh"
#include "pvr/frame/frame.h"

namespace pvr::cuda {

// The photon map the eye pass reads: exactly one of the two is set.
struct DeviceMap {
  const HashGridView* grid = nullptr;
  const KdTreeView* tree = nullptr;
};

// Events around each sample's eye-ray and density stages (grow-only, reused across frames).
struct EyeTimers {
  std::vector<std::unique_ptr<EventTimer>> rays, density;
  int used = 0;
  void prepare(int samples) {
    while (int(rays.size()) < samples) {
      rays.push_back(std::make_unique<EventTimer>());
      density.push_back(std::make_unique<EventTimer>());
    }
    used = samples;
  }
  // Waits for the events; sums over the samples.
  double raysMs() const {
    double t = 0;
    for (int s = 0; s < used; ++s) t += rays[s]->ms();
    return t;
  }
  double densityMs() const {
    double t = 0;
    for (int s = 0; s < used; ++s) t += density[s]->ms();
    return t;
  }
};

class GpuGather {
 public:
  // Shades one eye into image(eye) and firstPrim(eye); times its stages on `timers`.
  void renderEye(const DeviceScene& scene, DeviceMap map, const RenderOptions& options, const EyeCamera& camera,
                 Eye eye, cudaStream_t stream, EyeTimers& timers);
  const Vec3* image(Eye e) const { return images_[int(e)].data(); }
  const uint32_t* firstPrim(Eye e) const { return firstPrim_[int(e)].data(); }
  size_t memoryBytes() const;

 private:
  DeviceBuffer<Vec3> images_[2];
  DeviceBuffer<uint32_t> firstPrim_[2];
  DeviceBuffer<GatherPoint> points_;
  DeviceBuffer<uint32_t> sortKeys_[2], sortValues_[2];
  DeviceBuffer<unsigned char> temp_;
};

// Rays per second through the CUDA traversal, both eyes' pixels: primary rays, shadow rays to a
// light sample from each primary hit, and cosine-distributed diffuse rays from each primary hit.
struct RayThroughput {
  uint64_t primaryRays = 0, shadowRays = 0, diffuseRays = 0;
  double primaryMs = 0, shadowMs = 0, diffuseMs = 0;  ///< medians over the repeats
  std::vector<Hit> primaryHits;  ///< left eye's primary hits, for checking against the CPU
};
RayThroughput measureRayThroughput(const DeviceScene& scene, const StereoRig& rig, int repeats, cudaStream_t stream);

}  // namespace pvr::cuda
