#pragma once
// The photon-trace stage on the GPU: the shared tracePhoton per photon, the stored photons
// compacted in photon-index order (the CPU backend's order, so the two compare element by element).
#include <vector>

#include "pvr/accel/wide_bvh_traversal.h"
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
  // The same over the 8-wide BVH (`wide`, the scene's triangles in its own order): the same
  // photons, the closest hits being the same triangles.
  uint32_t trace(const DeviceScene& scene, const WideBvhIntersector& wide, const PhotonTraceParams& params,
                 cudaStream_t stream);
  const Photon* photons() const { return photons_.data(); }
  uint32_t count() const { return count_; }
  const Bounds3& bounds() const { return bounds_; }
  size_t memoryBytes() const;

 private:
  template <class Intersector>
  uint32_t traceWith(const SceneView& scene, const Intersector& intersector, const PhotonTraceParams& params,
                     cudaStream_t stream);
  DeviceBuffer<Photon> slots_, photons_;
  DeviceBuffer<uint32_t> counts_, offsets_;
  DeviceBuffer<uint32_t> summary_;  ///< the bounds (6, as orderedBits) and the next photon to start
  DeviceBuffer<unsigned char> temp_;
  uint32_t* hostSummary_ = nullptr;  ///< pinned: bounds and the chunk's count
  uint32_t count_ = 0;
  Bounds3 bounds_;
};

// A rolling photon map's slices on the device, each the photons of one trace, and all of them in
// one array for the map build (slice by slice, so in photon-index order when the slices are).
class RollingPhotons {
 public:
  // Replaces slice `slot` of `slots` (a new slot count empties all) by `count` photons at
  // `photons` (device) within `bounds`; reassembles the array.
  void store(int slot, int slots, const Photon* photons, uint32_t count, const Bounds3& bounds, cudaStream_t stream);
  const Photon* photons() const { return all_.data(); }
  uint32_t count() const { return count_; }
  const Bounds3& bounds() const { return bounds_; }
  size_t memoryBytes() const;

 private:
  struct Slice {
    DeviceBuffer<Photon> photons;
    uint32_t count = 0;
    Bounds3 bounds;
  };
  std::vector<Slice> slices_;
  DeviceBuffer<Photon> all_;
  uint32_t count_ = 0;
  Bounds3 bounds_;
};

}  // namespace pvr::cuda
