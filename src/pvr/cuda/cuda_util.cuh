#pragma once
// CUDA plumbing for the backend: error checks that throw pvr::Error (one clear line for the
// user, GPU out-of-memory included), labelled kernel launches (the label names the kernel in
// errors and, as an NVTX range, in nsys/ncu), device buffers that count the memory they hold, and
// event timing of stages.
#include <cuda_runtime.h>
#include <nvtx3/nvToolsExt.h>

#include <atomic>
#include <cstddef>
#include <string>
#include <utility>

#include "pvr/util/error.h"

namespace pvr::cuda {

[[noreturn]] void throwCudaError(cudaError_t error, const char* what, const char* file, int line);

#define PVR_CUDA_CHECK(call)                                                   \
  do {                                                                         \
    cudaError_t pvrCudaStatus_ = (call);                                       \
    if (pvrCudaStatus_ != cudaSuccess) ::pvr::cuda::throwCudaError(pvrCudaStatus_, #call, __FILE__, __LINE__); \
  } while (0)

// After a kernel launch: launch errors (bad configuration) surface here, naming the kernel;
// faults surface at the next sync.
[[noreturn]] void throwLaunchError(cudaError_t error, const char* label);
inline void checkLaunch(const char* label) {
  cudaError_t status = cudaPeekAtLastError();
  if (status != cudaSuccess) throwLaunchError(status, label);
}

// An NVTX range for the scope's life: profilers show the work under its label.
class NvtxRange {
 public:
  explicit NvtxRange(const char* label) { nvtxRangePushA(label); }
  ~NvtxRange() { nvtxRangePop(); }
  NvtxRange(const NvtxRange&) = delete;
  NvtxRange& operator=(const NvtxRange&) = delete;
};

#ifdef __CUDACC__
// Every kernel of the backend is launched through this: `label` says what it does ("eye rays").
template <class... Params, class... Args>
void launch(const char* label, void (*kernel)(Params...), dim3 grid, dim3 block, size_t sharedBytes,
            cudaStream_t stream, Args&&... args) {
  NvtxRange range(label);
  kernel<<<grid, block, sharedBytes, stream>>>(std::forward<Args>(args)...);
  checkLaunch(label);
}
#endif

// Bytes held by every DeviceBuffer, and the optional limit (PVR_GPU_MEMORY_LIMIT_MB) that makes
// allocations past it fail as if the GPU were out of memory.
size_t deviceBytesInUse();
void* deviceAllocate(size_t bytes, const char* what);
void deviceFree(void* p, size_t bytes);

template <class T>
class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  DeviceBuffer(DeviceBuffer&& o) noexcept { swap(o); }
  DeviceBuffer& operator=(DeviceBuffer&& o) noexcept {
    swap(o);
    return *this;
  }
  ~DeviceBuffer() { release(); }

  // Room for n elements; contents are discarded when the buffer grows.
  void reserve(size_t n, const char* what) {
    if (n <= capacity_) return;
    release();
    data_ = static_cast<T*>(deviceAllocate(n * sizeof(T), what));
    capacity_ = n;
  }
  void upload(const T* host, size_t n, const char* what, cudaStream_t stream = nullptr) {
    reserve(n, what);
    if (n) PVR_CUDA_CHECK(cudaMemcpyAsync(data_, host, n * sizeof(T), cudaMemcpyHostToDevice, stream));
  }
  void download(T* host, size_t n, cudaStream_t stream = nullptr) const {
    if (n) PVR_CUDA_CHECK(cudaMemcpyAsync(host, data_, n * sizeof(T), cudaMemcpyDeviceToHost, stream));
    PVR_CUDA_CHECK(cudaStreamSynchronize(stream));
  }
  void release() {
    if (data_) deviceFree(data_, capacity_ * sizeof(T));
    data_ = nullptr;
    capacity_ = 0;
  }
  T* data() const { return data_; }
  size_t capacity() const { return capacity_; }
  size_t bytes() const { return capacity_ * sizeof(T); }

 private:
  void swap(DeviceBuffer& o) noexcept {
    std::swap(data_, o.data_);
    std::swap(capacity_, o.capacity_);
  }
  T* data_ = nullptr;
  size_t capacity_ = 0;
};

// Times a region of a stream with a pair of events.
class EventTimer {
 public:
  EventTimer() {
    PVR_CUDA_CHECK(cudaEventCreate(&start_));
    PVR_CUDA_CHECK(cudaEventCreate(&stop_));
  }
  ~EventTimer() {
    cudaEventDestroy(start_);
    cudaEventDestroy(stop_);
  }
  EventTimer(const EventTimer&) = delete;
  EventTimer& operator=(const EventTimer&) = delete;
  void start(cudaStream_t s) { PVR_CUDA_CHECK(cudaEventRecord(start_, s)); }
  void stop(cudaStream_t s) { PVR_CUDA_CHECK(cudaEventRecord(stop_, s)); }
  // For scope ends (destructors): a failure here shows at the next checked call.
  void stopNoThrow(cudaStream_t s) noexcept { (void)cudaEventRecord(stop_, s); }
  // Waits for the stop event.
  double ms() const {
    PVR_CUDA_CHECK(cudaEventSynchronize(stop_));
    float v = 0;
    PVR_CUDA_CHECK(cudaEventElapsedTime(&v, start_, stop_));
    return double(v);
  }

 private:
  cudaEvent_t start_ = nullptr, stop_ = nullptr;
};

// Key bits a radix sort needs for keys in [0, values).
inline int radixBitsFor(uint64_t values) {
  int bits = 1;
  while (bits < 32 && (uint64_t(1) << bits) < values) ++bits;
  return bits;
}

// Streaming multiprocessors of the current device (for grid-stride launches that fill the GPU).
int multiprocessorCount();

inline unsigned blocksFor(size_t n, unsigned threads) { return unsigned((n + threads - 1) / threads); }

#ifdef __CUDACC__
// Adds the number of the calling warp's active threads whose `flag` is set to *counter: one atomic
// per warp, not per thread.
__device__ inline void countInWarp(unsigned* counter, bool flag) {
  unsigned active = __activemask();
  unsigned set = __ballot_sync(active, flag);
  unsigned lane = (threadIdx.z * blockDim.y * blockDim.x + threadIdx.y * blockDim.x + threadIdx.x) & 31u;
  if (lane == unsigned(__ffs(int(active)) - 1) && set) atomicAdd(counter, unsigned(__popc(int(set))));
}

// Appends `item` to list[*count] where `flag` is set, one atomic per block of `Threads` threads
// (every thread of the block must call it): a block's items stay together and in thread order, so
// that a kernel over the list sees the block's neighbourhood (a tile of pixels) together.
template <int Threads>
__device__ inline void appendInBlock(uint32_t* list, unsigned* count, bool flag, uint32_t item) {
  static_assert(Threads % 32 == 0, "whole warps");
  constexpr int kWarps = Threads / 32;
  __shared__ unsigned warpStart[kWarps + 1];
  const unsigned thread = (threadIdx.z * blockDim.y + threadIdx.y) * blockDim.x + threadIdx.x;
  const unsigned warp = thread / 32, lane = thread % 32;
  const unsigned set = __ballot_sync(0xffffffffu, flag);
  if (lane == 0) warpStart[warp + 1] = unsigned(__popc(int(set)));
  __syncthreads();
  if (thread == 0) {
    warpStart[0] = 0;
    for (int w = 1; w <= kWarps; ++w) warpStart[w] += warpStart[w - 1];
    const unsigned total = warpStart[kWarps];
    // The block's first slot, kept in the last entry's place once the sum is read.
    warpStart[kWarps] = total ? atomicAdd(count, total) : 0u;
  }
  __syncthreads();
  if (flag) list[warpStart[kWarps] + warpStart[warp] + unsigned(__popc(int(set & ((1u << lane) - 1u))))] = item;
}
#endif

}  // namespace pvr::cuda
