#pragma once
// The scene, its BVH, and the photon maps on the GPU. Photon tracing and both map builds run on
// the device with the same host+device code as the CPU backend; the results come out in the
// CPU backend's order (photon index, then a stable sort by cell), so the two can be compared
// element by element.
#include <vector>

#include "pvr/accel/bvh_traversal.h"
#include "pvr/cuda/cuda_util.cuh"
#include "pvr/photon/hash_grid.h"
#include "pvr/photon/kd_tree.h"
#include "pvr/photon/photon_trace.h"
#include "pvr/scene/scene.h"

namespace pvr::cuda {

struct DeviceScene {
  DeviceBuffer<Vec3> vertices, normals, faceNormals;
  DeviceBuffer<uint32_t> indices, materialIds, lightTriangles;
  DeviceBuffer<Material> materials;
  DeviceBuffer<float> lightCdf;
  DeviceBuffer<BvhNode> nodes;
  DeviceBuffer<BvhTriangle> triangles;
  SceneView view;
  BvhIntersector intersector;

  void upload(const Scene& scene, const Bvh& bvh);
};

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

// The paper's hash grid, built on the GPU: cell keys, CUB radix sort of (cell, index) pairs,
// startIdx by a scan of the cell counts, photons gathered in cell order.
class GpuHashGrid {
 public:
  void build(const Photon* photons, uint32_t count, const Bounds3& bounds, float radius, cudaStream_t stream);
  HashGridView view() const { return view_; }
  uint64_t cellCount() const { return cellCount_; }
  size_t memoryBytes() const;
  // Copies the grid back (tests): sorted photons, cellStart and the sorted-to-input permutation.
  void download(std::vector<Photon>& photons, std::vector<uint32_t>& cellStart, std::vector<uint32_t>& sortedToInput) const;

 private:
  DeviceBuffer<uint32_t> keys_[2], values_[2], counts_, cellStart_;
  DeviceBuffer<Photon> sorted_;
  DeviceBuffer<PackedPosition> positions_;
  DeviceBuffer<unsigned char> temp_;
  HashGridView view_;
  uint64_t cellCount_ = 0;
  int sortedBuffer_ = 0;
};

// The kd-tree baseline: photons copied to the host, built there (the CPU code), and uploaded.
// build() reports the three parts so that the comparison with the GPU-built grid is honest.
class GpuKdTree {
 public:
  struct Timing {
    double downloadMs = 0, buildMs = 0, uploadMs = 0;
  };
  Timing build(const Photon* photons, uint32_t count, cudaStream_t stream);
  KdTreeView view() const { return view_; }
  size_t memoryBytes() const { return photons_.bytes() + axes_.bytes(); }

 private:
  DeviceBuffer<Photon> photons_;
  DeviceBuffer<uint8_t> axes_;
  std::vector<Photon> host_;
  KdTreeView view_;
};

}  // namespace pvr::cuda
