#include "pvr/cuda/display_handover.h"

#include <unistd.h>

#include <cstring>

#include "pvr/cuda/cuda_util.cuh"

namespace pvr::cuda {
namespace {

__global__ void encodeEyeKernel(const Vec3* image, const float* inverseDepth, size_t pixels, float exposure,
                                DisplayEncoding encoding, float nearZ, unsigned char* colour, float* depth) {
  size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= pixels) return;
  encodeDisplayPixel(image[i], exposure, encoding, colour + i * size_t(displayBytesPerPixel(encoding)));
  if (depth && inverseDepth) depth[i] = reversedDepth(inverseDepth[i], nearZ);
}

}  // namespace

bool currentDeviceUuid(uint8_t uuid[16]) {
  int device = 0;
  cudaDeviceProp props;
  if (cudaGetDevice(&device) != cudaSuccess || cudaGetDeviceProperties(&props, device) != cudaSuccess) {
    cudaGetLastError();
    return false;
  }
  std::memcpy(uuid, props.uuid.bytes, 16);
  return true;
}

SharedBuffer::SharedBuffer(int fd, size_t allocationBytes, size_t usedBytes) {
  cudaExternalMemoryHandleDesc desc{};
  desc.type = cudaExternalMemoryHandleTypeOpaqueFd;
  desc.handle.fd = fd;
  desc.size = allocationBytes;
  desc.flags = cudaExternalMemoryDedicated;
  cudaExternalMemory_t memory;
  cudaError_t status = cudaImportExternalMemory(&memory, &desc);
  if (status != cudaSuccess) {
    close(fd);  // not taken over on failure
    throwCudaError(status, "importing a Vulkan buffer (cudaImportExternalMemory)", __FILE__, __LINE__);
  }
  memory_ = memory;
  cudaExternalMemoryBufferDesc buffer{};
  buffer.offset = 0;
  buffer.size = usedBytes;
  status = cudaExternalMemoryGetMappedBuffer(&data_, memory, &buffer);
  if (status != cudaSuccess) {
    cudaDestroyExternalMemory(memory);
    throwCudaError(status, "mapping a Vulkan buffer (cudaExternalMemoryGetMappedBuffer)", __FILE__, __LINE__);
  }
}

SharedBuffer::~SharedBuffer() {
  if (data_) cudaFree(data_);
  if (memory_) cudaDestroyExternalMemory(static_cast<cudaExternalMemory_t>(memory_));
}

SharedSemaphore::SharedSemaphore(int fd) {
  cudaExternalSemaphoreHandleDesc desc{};
  desc.type = cudaExternalSemaphoreHandleTypeOpaqueFd;
  desc.handle.fd = fd;
  cudaExternalSemaphore_t semaphore;
  cudaError_t status = cudaImportExternalSemaphore(&semaphore, &desc);
  if (status != cudaSuccess) {
    close(fd);
    throwCudaError(status, "importing a Vulkan semaphore (cudaImportExternalSemaphore)", __FILE__, __LINE__);
  }
  semaphore_ = semaphore;
}

SharedSemaphore::~SharedSemaphore() {
  if (semaphore_) cudaDestroyExternalSemaphore(static_cast<cudaExternalSemaphore_t>(semaphore_));
}

void SharedSemaphore::signal(void* stream) {
  cudaExternalSemaphoreSignalParams params{};
  cudaExternalSemaphore_t semaphore = static_cast<cudaExternalSemaphore_t>(semaphore_);
  PVR_CUDA_CHECK(cudaSignalExternalSemaphoresAsync(&semaphore, &params, 1, static_cast<cudaStream_t>(stream)));
}

HandOverStream::HandOverStream() {
  cudaStream_t s;
  cudaEvent_t a, b;
  PVR_CUDA_CHECK(cudaStreamCreateWithFlags(&s, cudaStreamNonBlocking));
  PVR_CUDA_CHECK(cudaEventCreate(&a));
  PVR_CUDA_CHECK(cudaEventCreate(&b));
  stream_ = s, start_ = a, stop_ = b;
}

HandOverStream::~HandOverStream() {
  cudaEventDestroy(static_cast<cudaEvent_t>(start_));
  cudaEventDestroy(static_cast<cudaEvent_t>(stop_));
  cudaStreamDestroy(static_cast<cudaStream_t>(stream_));
}

void HandOverStream::begin() { PVR_CUDA_CHECK(cudaEventRecord(static_cast<cudaEvent_t>(start_), static_cast<cudaStream_t>(stream_))); }
void HandOverStream::end() { PVR_CUDA_CHECK(cudaEventRecord(static_cast<cudaEvent_t>(stop_), static_cast<cudaStream_t>(stream_))); }

double HandOverStream::lastMs() {
  float ms = 0;
  PVR_CUDA_CHECK(cudaEventSynchronize(static_cast<cudaEvent_t>(stop_)));
  PVR_CUDA_CHECK(cudaEventElapsedTime(&ms, static_cast<cudaEvent_t>(start_), static_cast<cudaEvent_t>(stop_)));
  return ms;
}

void encodeEyeForDisplay(const Vec3* image, const float* inverseDepth, size_t pixels, float exposure,
                         DisplayEncoding encoding, float nearZ, void* colour, float* depth, void* stream) {
  if (!pixels) return;
  const int block = 256;
  launch("display hand-over encode", encodeEyeKernel, dim3(unsigned((pixels + block - 1) / block)), dim3(block), 0,
         static_cast<cudaStream_t>(stream), image, inverseDepth, pixels, exposure, encoding, nearZ,
         static_cast<unsigned char*>(colour), depth);
}

}  // namespace pvr::cuda
