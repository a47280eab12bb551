#pragma once
// The photon-trace stage on the GPU: the shared tracePhoton per photon, the stored photons
// compacted in photon-index order (the CPU backend's order, so the two compare element by element).
#include "pvr/cuda/device_scene.cuh"

namespace pvr::cuda {

// Photons traced on the GPU and compacted in photon-index order.
class GpuPhotonTracer {
 public:
  GpuPhotonTracer();
  ~GpuPhotonTracer();
  // Traces params.photonCount photons; returns how many were stored. Synchronizes the stream
  // once per chunk of photons (to learn the count and the photons' bounds).
  uint32_t trace(const DeviceScene& scene, const PhotonTraceParams& params, cudaStream_t stream);
  const Photon* photons() const { return photons_.data(); }
  uint32_t count() const { return count_; }
  const Bounds3& bounds() const { return bounds_; }
  size_t memoryBytes() const;

 private:
  DeviceBuffer<Photon> slots_, photons_;
  DeviceBuffer<uint32_t> counts_, offsets_;
  DeviceBuffer<int> summary_;  ///< 6 ordered-int bounds
  DeviceBuffer<unsigned char> temp_;
  int* hostSummary_ = nullptr;  ///< pinned: bounds and the chunk's count
  uint32_t count_ = 0;
  Bounds3 bounds_;
};

}  // namespace pvr::cuda
