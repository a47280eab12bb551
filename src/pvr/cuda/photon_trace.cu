#include <cub/device/device_scan.cuh>

#include <algorithm>

#include "pvr/cuda/photon_trace.cuh"
#include "pvr/cuda/traversal_stack.cuh"

namespace pvr::cuda {
namespace {

constexpr int kPhotonBlock = 128;

// Persistent lanes: a lane whose path ended takes the next photon index (a warp fetches for all
// its idle lanes with one atomic) and starts it at once, so that the warp's lanes keep tracing
// instead of idling until its longest path ends (Aila and Laine 2009). A photon's random numbers
// and output slots follow its index, so the result does not depend on which lane traced it.
template <class Intersector>
__global__ void __launch_bounds__(kPhotonBlock) tracePhotonsKernel(SceneView scene, Intersector sceneIntersector,
                                                                   PhotonTraceParams params, uint32_t first, uint32_t n,
                                                                   Photon* slots, uint32_t* counts, uint32_t* bounds,
                                                                   uint32_t* nextPhoton) {
  const Intersector intersector = withSharedStack<kPhotonBlock>(sceneIntersector);
  const unsigned lane = threadIdx.x & 31u;
  Bounds3 b;
  PhotonPath path;
  bool tracing = false, drained = false;
  while (true) {
    const unsigned idle = __ballot_sync(0xffffffffu, !tracing && !drained);
    if (idle) {
      uint32_t base = 0;
      if (lane == unsigned(__ffs(idle) - 1)) base = atomicAdd(nextPhoton, uint32_t(__popc(idle)));
      base = __shfl_sync(0xffffffffu, base, __ffs(idle) - 1);
      if (idle & (1u << lane)) {
        const uint32_t i = base + uint32_t(__popc(idle & ((1u << lane) - 1u)));
        if (i < n) path = startPhotonPath(scene, params, first + i), tracing = true;
        else drained = true;
      }
    }
    if (__all_sync(0xffffffffu, drained)) break;
    if (!tracing) continue;
    const uint32_t i = path.index - first;
    Photon* out = slots + size_t(i) * params.maxDepth;
    if (!advancePhotonPath(scene, intersector, params, path, out)) {
      counts[i] = uint32_t(path.stored);
      for (int k = 0; k < path.stored; ++k) b.extend(out[k].position);
      tracing = false;
    }
  }
  // Warp-reduce the bounds, then one lane updates the global bounds.
  float v[6] = {b.lower.x, b.lower.y, b.lower.z, b.upper.x, b.upper.y, b.upper.z};
  for (int offset = 16; offset > 0; offset >>= 1)
    for (int a = 0; a < 6; ++a) {
      float o = __shfl_xor_sync(0xffffffffu, v[a], offset);
      v[a] = a < 3 ? fminf(v[a], o) : fmaxf(v[a], o);
    }
  if (lane == 0 && v[0] <= v[3]) {
    for (int a = 0; a < 3; ++a) {
      atomicMin(bounds + a, orderedBits(v[a]));
      atomicMax(bounds + 3 + a, orderedBits(v[3 + a]));
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

}  // namespace

GpuPhotonTracer::GpuPhotonTracer() { PVR_CUDA_CHECK(cudaMallocHost(&hostSummary_, 8 * sizeof(uint32_t))); }
GpuPhotonTracer::~GpuPhotonTracer() { cudaFreeHost(hostSummary_); }

size_t GpuPhotonTracer::memoryBytes() const {
  return slots_.bytes() + photons_.bytes() + counts_.bytes() + offsets_.bytes() + summary_.bytes() + temp_.bytes();
}

uint32_t GpuPhotonTracer::trace(const DeviceScene& scene, const PhotonTraceParams& params, cudaStream_t stream) {
  return traceWith(scene.view, scene.intersector, params, stream);
}

uint32_t GpuPhotonTracer::trace(const DeviceScene& scene, const WideBvhIntersector& wide, const PhotonTraceParams& params,
                                cudaStream_t stream) {
  return traceWith(scene.view, wide, params, stream);
}

template <class Intersector>
uint32_t GpuPhotonTracer::traceWith(const SceneView& scene, const Intersector& intersector, const PhotonTraceParams& params,
                                    cudaStream_t stream) {
  const int slotsPerPhoton = std::max(params.maxDepth, 1);
  // Chunks bound the scratch slots to 256 MiB whatever the photon count and depth.
  const uint32_t last = params.lastPhoton();
  const uint32_t traced = last > params.firstPhoton ? last - params.firstPhoton : 0;
  const uint32_t chunk = uint32_t(
      std::clamp<uint64_t>((uint64_t(256) << 20) / (sizeof(Photon) * slotsPerPhoton), 1024, std::max<uint32_t>(traced, 1024)));
  slots_.reserve(size_t(chunk) * slotsPerPhoton, "photon scratch slots");
  counts_.reserve(size_t(chunk) + 1, "photon counts");
  offsets_.reserve(size_t(chunk) + 1, "photon offsets");
  summary_.reserve(8, "photon bounds");
  size_t tempBytes = 0;
  PVR_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, tempBytes, counts_.data(), offsets_.data(), chunk + 1, stream));
  temp_.reserve(tempBytes, "photon scan scratch");

  // As many blocks as stay resident: the lanes take photons until none are left.
  static const unsigned residentBlocks = [] {
    int perMultiprocessor = 0;
    PVR_CUDA_CHECK(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&perMultiprocessor, tracePhotonsKernel<Intersector>,
                                                                 kPhotonBlock, 0));
    return unsigned(std::max(perMultiprocessor, 1) * multiprocessorCount());
  }();
  uint32_t init[6];
  for (int a = 0; a < 3; ++a) init[a] = orderedBits(INFINITY), init[3 + a] = orderedBits(-INFINITY);
  PVR_CUDA_CHECK(cudaMemcpyAsync(summary_.data(), init, sizeof init, cudaMemcpyHostToDevice, stream));
  uint32_t stored = 0;
  for (uint32_t first = params.firstPhoton; first < last; first += chunk) {
    uint32_t n = std::min(chunk, last - first);
    PVR_CUDA_CHECK(cudaMemsetAsync(counts_.data() + n, 0, sizeof(uint32_t), stream));
    PVR_CUDA_CHECK(cudaMemsetAsync(summary_.data() + 6, 0, sizeof(uint32_t), stream));  // the next photon to start
    launch("photon trace", tracePhotonsKernel<Intersector>, std::min(blocksFor(n, kPhotonBlock), residentBlocks),
           kPhotonBlock, 0, stream, scene, intersector, params, first, n, slots_.data(), counts_.data(),
           summary_.data(), summary_.data() + 6);
    size_t bytes = temp_.capacity();
    PVR_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(temp_.data(), bytes, counts_.data(), offsets_.data(), n + 1, stream));
    PVR_CUDA_CHECK(cudaMemcpyAsync(hostSummary_, summary_.data(), 6 * sizeof(uint32_t), cudaMemcpyDeviceToHost, stream));
    PVR_CUDA_CHECK(cudaMemcpyAsync(hostSummary_ + 6, offsets_.data() + n, sizeof(uint32_t), cudaMemcpyDeviceToHost, stream));
    PVR_CUDA_CHECK(cudaStreamSynchronize(stream));
    uint32_t added = hostSummary_[6];
    if (size_t(stored) + added > photons_.capacity()) {  // grow, keeping earlier chunks
      DeviceBuffer<Photon> bigger;
      bigger.reserve(std::max<size_t>(size_t(stored + added) * 5 / 4, 1024), "stored photons");
      if (stored)
        PVR_CUDA_CHECK(cudaMemcpyAsync(bigger.data(), photons_.data(), stored * sizeof(Photon),
                                       cudaMemcpyDeviceToDevice, stream));
      photons_ = std::move(bigger);
    }
    launch("photon compaction", compactPhotonsKernel, blocksFor(n, 256), 256, 0, stream, slots_.data(), counts_.data(),
           offsets_.data(), n, slotsPerPhoton, photons_.data() + stored);
    stored += added;
  }
  count_ = stored;
  bounds_ = Bounds3();
  if (stored) {
    bounds_.lower = {fromOrderedBits(hostSummary_[0]), fromOrderedBits(hostSummary_[1]), fromOrderedBits(hostSummary_[2])};
    bounds_.upper = {fromOrderedBits(hostSummary_[3]), fromOrderedBits(hostSummary_[4]), fromOrderedBits(hostSummary_[5])};
  }
  return stored;
}

void RollingPhotons::store(int slot, int slots, const Photon* photons, uint32_t count, const Bounds3& bounds,
                           cudaStream_t stream) {
  if (int(slices_.size()) != slots) slices_ = std::vector<Slice>(size_t(slots));
  Slice& s = slices_[size_t(slot)];
  s.photons.reserve(std::max<size_t>(size_t(count) * 5 / 4, 1024), "rolling photon slice");
  if (count)
    PVR_CUDA_CHECK(cudaMemcpyAsync(s.photons.data(), photons, count * sizeof(Photon), cudaMemcpyDeviceToDevice, stream));
  s.count = count;
  s.bounds = bounds;
  size_t total = 0;
  bounds_ = Bounds3();
  for (const Slice& x : slices_) {
    total += x.count;
    if (x.count) bounds_.extend(x.bounds.lower), bounds_.extend(x.bounds.upper);
  }
  all_.reserve(std::max<size_t>(total * 5 / 4, 1024), "rolling photon map");
  size_t at = 0;
  for (const Slice& x : slices_) {
    if (x.count)
      PVR_CUDA_CHECK(cudaMemcpyAsync(all_.data() + at, x.photons.data(), x.count * sizeof(Photon), cudaMemcpyDeviceToDevice,
                                     stream));
    at += x.count;
  }
  count_ = uint32_t(total);
}

size_t RollingPhotons::memoryBytes() const {
  size_t bytes = all_.bytes();
  for (const Slice& x : slices_) bytes += x.photons.bytes();
  return bytes;
}

}  // namespace pvr::cuda
