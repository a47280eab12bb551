#pragma once
// The map-build stage on the GPU: the hash grid (CUB sort and scan; the CPU builder's cells and
// order) and the kd-tree baseline (built on the host).
#include "pvr/cuda/device_scene.cuh"

namespace pvr::cuda {

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
