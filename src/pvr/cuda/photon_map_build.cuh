#pragma once
// The map-build stage on the GPU: the hash grid (CUB sort and scan; the CPU builder's cells and
// order) and the kd-tree baseline (built level by level).
#include "pvr/cuda/device_scene.cuh"

namespace pvr::cuda {

// The paper's hash grid, built on the GPU: cell keys, CUB radix sort of (cell, index) pairs,
// startIdx from a search of the sorted keys per cell, photons gathered in cell order.
class GpuHashGrid {
 public:
  void build(const Photon* photons, uint32_t count, const Bounds3& bounds, float radius, cudaStream_t stream);
  HashGridView view() const { return view_; }
  uint64_t cellCount() const { return cellCount_; }
  size_t memoryBytes() const;
  // Copies the grid back (tests): sorted photons, cellStart and the sorted-to-input permutation.
  void download(std::vector<Photon>& photons, std::vector<uint32_t>& cellStart, std::vector<uint32_t>& sortedToInput) const;

 private:
  DeviceBuffer<uint32_t> keys_[2], values_[2], cellStart_;
  DeviceBuffer<Photon> sorted_;
  DeviceBuffer<PackedPosition> positions_;
  DeviceBuffer<unsigned char> temp_;
  HashGridView view_;
  uint64_t cellCount_ = 0;
  int sortedBuffer_ = 0;
};

// The kd-tree baseline, built on the GPU level by level: the same tree as the CPU build
// (photon/kd_tree.h). Each photon's rank along each axis, by (coordinate, index), comes from
// three stable radix sorts; then per level, the bounds of every node's photons (warp-aggregated
// atomics), its longest axis, and one radix sort of all slots by (node's first slot, rank along
// the node's axis) put each node's median photon at its split.
class GpuKdTree {
 public:
  void build(const Photon* photons, uint32_t count, cudaStream_t stream);
  KdTreeView view() const { return view_; }
  size_t memoryBytes() const;
  // Copies the tree back (tests): photons in node order, split axes, node -> input index.
  void download(std::vector<Photon>& photons, std::vector<uint8_t>& axes, std::vector<uint32_t>& nodeToInput) const;

 private:
  DeviceBuffer<Photon> photons_;
  DeviceBuffer<uint8_t> axes_;
  DeviceBuffer<uint32_t> nodeToInput_, ranks_, order_[2], boundsLower_, boundsUpper_;
  DeviceBuffer<uint64_t> keys_[2];
  DeviceBuffer<unsigned char> temp_;
  KdTreeView view_;
};

}  // namespace pvr::cuda
