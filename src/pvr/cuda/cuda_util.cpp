#include <cstdio>
#include <cstdlib>
#include <string>

#include "pvr/cuda/cuda_util.cuh"
#include "pvr/util/fault_injection.h"

namespace pvr::cuda {
namespace {

std::atomic<size_t> gBytesInUse{0};

size_t memoryLimitBytes() {
  static const size_t limit = [] {
    const char* text = std::getenv("PVR_GPU_MEMORY_LIMIT_MB");
    if (!text || !*text) return size_t(0);
    char* end = nullptr;
    unsigned long long mb = std::strtoull(text, &end, 10);
    if (*end != '\0') throw Error("PVR_GPU_MEMORY_LIMIT_MB must be a whole number of MiB, got '" + std::string(text) + "'");
    return size_t(mb) << 20;
  }();
  return limit;
}

std::string mib(size_t bytes) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.1f MiB", double(bytes) / 1048576.0);
  return buffer;
}

}  // namespace

// Errors after which the CUDA context is unusable: every later call fails the same way, so the
// only way on is a clean exit (a new process gets a new context).
static bool contextLost(cudaError_t error) {
  switch (error) {
    case cudaErrorLaunchFailure:
    case cudaErrorIllegalAddress:
    case cudaErrorIllegalInstruction:
    case cudaErrorMisalignedAddress:
    case cudaErrorInvalidAddressSpace:
    case cudaErrorInvalidPc:
    case cudaErrorHardwareStackError:
    case cudaErrorAssert:
    case cudaErrorLaunchTimeout:
    case cudaErrorECCUncorrectable: return true;
    default: return false;
  }
}

// One line for the user: out of memory, a lost context, or any other CUDA error, with where.
[[noreturn]] static void throwCudaStatus(cudaError_t error, const std::string& where) {
  if (error == cudaErrorMemoryAllocation) throw Error("GPU out of memory (" + where + ")");
  if (contextLost(error))
    throw Error(std::string("the GPU device was lost: ") + cudaGetErrorString(error) + " (" + where +
                "); photonvr cannot continue on this CUDA context");
  throw Error(std::string("CUDA error: ") + cudaGetErrorString(error) + " (" + where + ")");
}

void throwCudaError(cudaError_t error, const char* what, const char* file, int line) {
  std::string where = std::string(file);
  where = where.substr(where.find_last_of('/') + 1) + ":" + std::to_string(line);
  throwCudaStatus(error, std::string(what) + " at " + where);
}

void throwLaunchError(cudaError_t error, const char* label) {
  cudaGetLastError();  // a launch error is not sticky (a lost context's is, and stays)
  // A fault of an earlier kernel can surface at this launch: the context is then lost.
  throwCudaStatus(error, std::string("launching the ") + label + " kernel");
}

size_t deviceBytesInUse() { return gBytesInUse.load(); }

void* deviceAllocate(size_t bytes, const char* what) {
  if (bytes == 0) bytes = 1;
  size_t limit = memoryLimitBytes();
  if (limit && gBytesInUse.load() + bytes > limit)
    throw Error("GPU out of memory: " + std::string(what) + " needs " + mib(bytes) + ", " + mib(gBytesInUse.load()) +
                " already in use, limit " + mib(limit) + " (PVR_GPU_MEMORY_LIMIT_MB)");
  void* p = nullptr;
  cudaError_t status = faultInjected(Fault::GpuAllocation) ? cudaErrorMemoryAllocation : cudaMalloc(&p, bytes);
  if (status == cudaErrorMemoryAllocation) {
    cudaGetLastError();  // not sticky: clear it so later calls do not report it
    size_t freeBytes = 0, total = 0;
    cudaMemGetInfo(&freeBytes, &total);
    throw Error("GPU out of memory: " + std::string(what) + " needs " + mib(bytes) + ", " + mib(freeBytes) +
                " free of " + mib(total));
  }
  if (status != cudaSuccess) throwCudaError(status, what, __FILE__, __LINE__);
  gBytesInUse += bytes;
  return p;
}

void deviceFree(void* p, size_t bytes) {
  if (!p) return;
  cudaFree(p);
  gBytesInUse -= bytes == 0 ? 1 : bytes;
}

int multiprocessorCount() {
  int device = 0, count = 0;
  PVR_CUDA_CHECK(cudaGetDevice(&device));
  PVR_CUDA_CHECK(cudaDeviceGetAttribute(&count, cudaDevAttrMultiProcessorCount, device));
  return count;
}

}  // namespace pvr::cuda
