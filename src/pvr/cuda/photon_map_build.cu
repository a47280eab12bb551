#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>

#include <algorithm>
#include <chrono>

#include "pvr/cuda/photon_map_build.cuh"

namespace pvr::cuda {
namespace {

__global__ void cellKeysKernel(HashGridView grid, const Photon* photons, uint32_t n, uint32_t* keys,
                               uint32_t* values, uint32_t* cellCounts) {
  uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  int64_t c = grid.cellOf(photons[i].position);
  uint32_t key = c < 0 ? 0u : uint32_t(c);  // bounds come from these photons: always inside
  keys[i] = key;
  values[i] = i;
  atomicAdd(cellCounts + key, 1u);
}

__global__ void gatherPhotonsKernel(const Photon* photons, const uint32_t* order, uint32_t n, Photon* sorted,
                                    PackedPosition* positions) {
  uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  Photon p = photons[order[i]];
  sorted[i] = p;
  positions[i] = {p.position.x, p.position.y, p.position.z, 0.0f};
}

}  // namespace

size_t GpuHashGrid::memoryBytes() const {
  return keys_[0].bytes() + keys_[1].bytes() + values_[0].bytes() + values_[1].bytes() + counts_.bytes() +
         cellStart_.bytes() + sorted_.bytes() + positions_.bytes() + temp_.bytes();
}

void GpuHashGrid::build(const Photon* photons, uint32_t count, const Bounds3& bounds, float radius,
                        cudaStream_t stream) {
  view_ = hashGridLayout(bounds, radius);  // the CPU builder's layout: same cells, same order
  cellCount_ = uint64_t(view_.dims[0]) * view_.dims[1] * view_.dims[2];
  size_t n = std::max<size_t>(count, 1);
  for (int b = 0; b < 2; ++b) {
    keys_[b].reserve(n, "hash-grid keys");
    values_[b].reserve(n, "hash-grid permutation");
  }
  counts_.reserve(cellCount_ + 1, "hash-grid cell counts");
  cellStart_.reserve(cellCount_ + 1, "hash-grid startIdx");
  sorted_.reserve(n, "hash-grid photons");
  positions_.reserve(n, "hash-grid positions");
  int endBit = radixBitsFor(cellCount_);
  cub::DoubleBuffer<uint32_t> keys(keys_[0].data(), keys_[1].data()), values(values_[0].data(), values_[1].data());
  size_t sortBytes = 0, scanBytes = 0;
  PVR_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, sortBytes, keys, values, int(n), 0, endBit, stream));
  PVR_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, scanBytes, counts_.data(), cellStart_.data(),
                                               int(cellCount_ + 1), stream));
  temp_.reserve(std::max(sortBytes, scanBytes), "hash-grid sort scratch");

  PVR_CUDA_CHECK(cudaMemsetAsync(counts_.data(), 0, (cellCount_ + 1) * sizeof(uint32_t), stream));
  if (count) {
    launch("hash-grid cell keys", cellKeysKernel, blocksFor(count, 256), 256, 0, stream, view_, photons, count,
           keys_[0].data(), values_[0].data(), counts_.data());
  }
  size_t bytes = temp_.capacity();
  PVR_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(temp_.data(), bytes, counts_.data(), cellStart_.data(),
                                               int(cellCount_ + 1), stream));
  if (count) {
    bytes = temp_.capacity();
    PVR_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp_.data(), bytes, keys, values, int(count), 0, endBit, stream));
    sortedBuffer_ = keys.selector;
    launch("hash-grid photons in cell order", gatherPhotonsKernel, blocksFor(count, 256), 256, 0, stream, photons,
           values.Current(), count, sorted_.data(), positions_.data());
  }
  view_.photons = sorted_.data();
  view_.positions = positions_.data();
  view_.cellStart = cellStart_.data();
  view_.photonCount = count;
}

void GpuHashGrid::download(std::vector<Photon>& photons, std::vector<uint32_t>& cellStart,
                           std::vector<uint32_t>& sortedToInput) const {
  photons.resize(view_.photonCount);
  sortedToInput.resize(view_.photonCount);
  cellStart.resize(cellCount_ + 1);
  sorted_.download(photons.data(), photons.size());
  values_[sortedBuffer_].download(sortedToInput.data(), sortedToInput.size());
  cellStart_.download(cellStart.data(), cellStart.size());
}

GpuKdTree::Timing GpuKdTree::build(const Photon* photons, uint32_t count, cudaStream_t stream) {
  using Clock = std::chrono::steady_clock;
  auto ms = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
  Timing t;
  auto t0 = Clock::now();
  host_.resize(count);
  if (count) PVR_CUDA_CHECK(cudaMemcpyAsync(host_.data(), photons, count * sizeof(Photon), cudaMemcpyDeviceToHost, stream));
  PVR_CUDA_CHECK(cudaStreamSynchronize(stream));
  auto t1 = Clock::now();
  KdTree tree = KdTree::build(host_);
  auto t2 = Clock::now();
  photons_.upload(tree.photons().data(), count, "kd-tree photons", stream);
  KdTreeView hostView = tree.view();
  axes_.upload(hostView.axes, count, "kd-tree axes", stream);
  PVR_CUDA_CHECK(cudaStreamSynchronize(stream));  // the host tree dies here
  auto t3 = Clock::now();
  t.downloadMs = ms(t0, t1), t.buildMs = ms(t1, t2), t.uploadMs = ms(t2, t3);
  view_ = {photons_.data(), axes_.data(), count};
  return t;
}

}  // namespace pvr::cuda
