#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>

#include <algorithm>
#include <chrono>

#include "pvr/cuda/gpu_scene.cuh"

namespace pvr::cuda {
namespace {

// Floats as ints whose order is the floats' order, for atomicMin/atomicMax on bounds.
PVR_HOST_DEVICE inline int orderedFromFloat(float f) {
  int i = int(floatBits(f));
  return i >= 0 ? i : i ^ 0x7FFFFFFF;
}
PVR_HOST_DEVICE inline float floatFromOrdered(int i) {
  return floatFromBits(uint32_t(i >= 0 ? i : i ^ 0x7FFFFFFF));
}

__global__ void tracePhotonsKernel(SceneView scene, BvhIntersector intersector, PhotonTraceParams params,
                                   uint32_t first, uint32_t n, Photon* slots, uint32_t* counts, int* bounds) {
  uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  Bounds3 b;
  if (i < n) {
    Photon* out = slots + size_t(i) * params.maxDepth;
    int stored = tracePhoton(scene, intersector, params, first + i, out);
    counts[i] = uint32_t(stored);
    for (int k = 0; k < stored; ++k) b.extend(out[k].position);
  }
  // Warp-reduce the bounds, then one lane updates the global bounds.
  float v[6] = {b.lower.x, b.lower.y, b.lower.z, b.upper.x, b.upper.y, b.upper.z};
  for (int offset = 16; offset > 0; offset >>= 1)
    for (int a = 0; a < 6; ++a) {
      float o = __shfl_xor_sync(0xffffffffu, v[a], offset);
      v[a] = a < 3 ? fminf(v[a], o) : fmaxf(v[a], o);
    }
  if ((threadIdx.x & 31) == 0 && v[0] <= v[3]) {
    for (int a = 0; a < 3; ++a) {
      atomicMin(bounds + a, orderedFromFloat(v[a]));
      atomicMax(bounds + 3 + a, orderedFromFloat(v[3 + a]));
    }
  }
}

__global__ void compactPhotonsKernel(const Photon* slots, const uint32_t* counts, const uint32_t* offsets, uint32_t n,
                                     int slotsPerPhoton, Photon* out) {
  uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const Photon* src = slots + size_t(i) * slotsPerPhoton;
  Photon* dst = out + offsets[i];
  for (uint32_t k = 0; k < counts[i]; ++k) dst[k] = src[k];
}

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

void DeviceScene::upload(const Scene& scene, const Bvh& bvh) {
  SceneView host = scene.view();
  size_t vertexCount = scene.vertices().size();
  vertices.upload(scene.vertices().data(), vertexCount, "scene vertices");
  if (host.normals) normals.upload(host.normals, vertexCount, "scene normals");
  faceNormals.upload(scene.faceNormals().data(), scene.faceNormals().size(), "face normals");
  indices.upload(host.indices, 3 * size_t(host.triangleCount), "scene indices");
  materialIds.upload(host.materialIds, host.triangleCount, "material ids");
  materials.upload(scene.materials().data(), scene.materials().size(), "materials");
  lightTriangles.upload(host.lightTriangles, host.lightCount, "light triangles");
  lightCdf.upload(host.lightCdf, size_t(host.lightCount) + 1, "light CDF");
  nodes.upload(bvh.nodes().data(), bvh.nodes().size(), "BVH nodes");
  triangles.upload(bvh.triangles().data(), bvh.triangles().size(), "BVH triangles");
  PVR_CUDA_CHECK(cudaDeviceSynchronize());
  view = host;
  view.vertices = vertices.data();
  view.normals = host.normals ? normals.data() : nullptr;
  view.faceNormals = faceNormals.data();
  view.indices = indices.data();
  view.materialIds = materialIds.data();
  view.materials = materials.data();
  view.lightTriangles = lightTriangles.data();
  view.lightCdf = lightCdf.data();
  intersector.bvh = {nodes.data(), triangles.data(), uint32_t(bvh.nodes().size()), uint32_t(bvh.triangles().size())};
}

GpuPhotonTracer::GpuPhotonTracer() { PVR_CUDA_CHECK(cudaMallocHost(&hostSummary_, 8 * sizeof(int))); }
GpuPhotonTracer::~GpuPhotonTracer() { cudaFreeHost(hostSummary_); }

size_t GpuPhotonTracer::memoryBytes() const {
  return slots_.bytes() + photons_.bytes() + counts_.bytes() + offsets_.bytes() + summary_.bytes() + temp_.bytes();
}

uint32_t GpuPhotonTracer::trace(const DeviceScene& scene, const PhotonTraceParams& params, cudaStream_t stream) {
  const int slotsPerPhoton = std::max(params.maxDepth, 1);
  // Chunks bound the scratch slots to 256 MiB whatever the photon count and depth.
  const uint32_t chunk =
      uint32_t(std::clamp<uint64_t>((uint64_t(256) << 20) / (sizeof(Photon) * slotsPerPhoton), 1024, params.photonCount));
  slots_.reserve(size_t(chunk) * slotsPerPhoton, "photon scratch slots");
  counts_.reserve(size_t(chunk) + 1, "photon counts");
  offsets_.reserve(size_t(chunk) + 1, "photon offsets");
  summary_.reserve(8, "photon bounds");
  size_t tempBytes = 0;
  PVR_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, tempBytes, counts_.data(), offsets_.data(), chunk + 1, stream));
  temp_.reserve(tempBytes, "photon scan scratch");

  int init[6];
  for (int a = 0; a < 3; ++a) init[a] = orderedFromFloat(INFINITY), init[3 + a] = orderedFromFloat(-INFINITY);
  PVR_CUDA_CHECK(cudaMemcpyAsync(summary_.data(), init, sizeof init, cudaMemcpyHostToDevice, stream));
  uint32_t stored = 0;
  for (uint32_t first = 0; first < params.photonCount; first += chunk) {
    uint32_t n = std::min(chunk, params.photonCount - first);
    PVR_CUDA_CHECK(cudaMemsetAsync(counts_.data() + n, 0, sizeof(uint32_t), stream));
    tracePhotonsKernel<<<blocksFor(n, 128), 128, 0, stream>>>(scene.view, scene.intersector, params, first, n,
                                                               slots_.data(), counts_.data(), summary_.data());
    PVR_CUDA_CHECK_LAUNCH("tracePhotons");
    size_t bytes = temp_.capacity();
    PVR_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(temp_.data(), bytes, counts_.data(), offsets_.data(), n + 1, stream));
    PVR_CUDA_CHECK(cudaMemcpyAsync(hostSummary_, summary_.data(), 6 * sizeof(int), cudaMemcpyDeviceToHost, stream));
    PVR_CUDA_CHECK(cudaMemcpyAsync(hostSummary_ + 6, offsets_.data() + n, sizeof(uint32_t), cudaMemcpyDeviceToHost, stream));
    PVR_CUDA_CHECK(cudaStreamSynchronize(stream));
    uint32_t added = uint32_t(hostSummary_[6]);
    if (size_t(stored) + added > photons_.capacity()) {  // grow, keeping earlier chunks
      DeviceBuffer<Photon> bigger;
      bigger.reserve(std::max<size_t>(size_t(stored + added) * 5 / 4, 1024), "stored photons");
      if (stored)
        PVR_CUDA_CHECK(cudaMemcpyAsync(bigger.data(), photons_.data(), stored * sizeof(Photon),
                                       cudaMemcpyDeviceToDevice, stream));
      photons_ = std::move(bigger);
    }
    compactPhotonsKernel<<<blocksFor(n, 256), 256, 0, stream>>>(slots_.data(), counts_.data(), offsets_.data(), n,
                                                                 slotsPerPhoton, photons_.data() + stored);
    PVR_CUDA_CHECK_LAUNCH("compactPhotons");
    stored += added;
  }
  count_ = stored;
  bounds_ = Bounds3();
  if (stored) {
    bounds_.lower = {floatFromOrdered(hostSummary_[0]), floatFromOrdered(hostSummary_[1]), floatFromOrdered(hostSummary_[2])};
    bounds_.upper = {floatFromOrdered(hostSummary_[3]), floatFromOrdered(hostSummary_[4]), floatFromOrdered(hostSummary_[5])};
  }
  return stored;
}

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
    cellKeysKernel<<<blocksFor(count, 256), 256, 0, stream>>>(view_, photons, count, keys_[0].data(), values_[0].data(),
                                                              counts_.data());
    PVR_CUDA_CHECK_LAUNCH("cellKeys");
  }
  size_t bytes = temp_.capacity();
  PVR_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(temp_.data(), bytes, counts_.data(), cellStart_.data(),
                                               int(cellCount_ + 1), stream));
  if (count) {
    bytes = temp_.capacity();
    PVR_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp_.data(), bytes, keys, values, int(count), 0, endBit, stream));
    sortedBuffer_ = keys.selector;
    gatherPhotonsKernel<<<blocksFor(count, 256), 256, 0, stream>>>(photons, values.Current(), count, sorted_.data(),
                                                                   positions_.data());
    PVR_CUDA_CHECK_LAUNCH("gatherPhotons");
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
