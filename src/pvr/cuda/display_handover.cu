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
  if (depth) depth[i] = inverseDepth ? reversedDepth(inverseDepth[i], nearZ) : 0.0f;
}

__global__ void encodeEyeSurfaceKernel(const Vec3* image, const float* inverseDepth, int width, int height, float exposure,
                                       DisplayEncoding encoding, float nearZ, cudaSurfaceObject_t surface, float* depth) {
  int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= width || y >= height) return;
  size_t i = size_t(y) * width + x;
  unsigned char texel[8];
  encodeDisplayPixel(image[i], exposure, encoding, texel);
  if (displayBytesPerPixel(encoding) == 8) {
    uint2 v;
    memcpy(&v, texel, 8);
    surf2Dwrite(v, surface, x * 8, y);
  } else {
    uint32_t v;
    memcpy(&v, texel, 4);
    surf2Dwrite(v, surface, x * 4, y);
  }
  if (depth) depth[i] = inverseDepth ? reversedDepth(inverseDepth[i], nearZ) : 0.0f;
}

// A dedicated Vulkan allocation (an opaque fd) imported into CUDA, which takes the fd over; on
// failure the fd is closed here and `what` names the step.
cudaExternalMemory_t importVulkanMemory(int fd, size_t allocationBytes, const char* what) {
  cudaExternalMemoryHandleDesc desc{};
  desc.type = cudaExternalMemoryHandleTypeOpaqueFd;
  desc.handle.fd = fd;
  desc.size = allocationBytes;
  desc.flags = cudaExternalMemoryDedicated;
  cudaExternalMemory_t memory;
  cudaError_t status = cudaImportExternalMemory(&memory, &desc);
  if (status != cudaSuccess) {
    close(fd);  // not taken over on failure
    throwCudaError(status, what, __FILE__, __LINE__);
  }
  return memory;
}

}  // namespace

SharedSurface::SharedSurface(int fd, size_t allocationBytes, int width, int height, int bytesPerPixel) {
  cudaExternalMemory_t memory = importVulkanMemory(fd, allocationBytes, "importing a Vulkan image (cudaImportExternalMemory)");
  memory_ = memory;
  cudaExternalMemoryMipmappedArrayDesc arrayDesc{};
  arrayDesc.offset = 0;
  arrayDesc.formatDesc = bytesPerPixel == 8 ? cudaCreateChannelDesc(16, 16, 16, 16, cudaChannelFormatKindFloat)
                                            : cudaCreateChannelDesc(8, 8, 8, 8, cudaChannelFormatKindUnsigned);
  arrayDesc.extent = make_cudaExtent(size_t(width), size_t(height), 0);
  arrayDesc.flags = cudaArraySurfaceLoadStore;
  arrayDesc.numLevels = 1;
  cudaMipmappedArray_t mipmapped;
  cudaError_t status = cudaExternalMemoryGetMappedMipmappedArray(&mipmapped, memory, &arrayDesc);
  if (status != cudaSuccess) {
    cudaDestroyExternalMemory(memory);
    memory_ = nullptr;
    throwCudaError(status, "mapping a Vulkan image (cudaExternalMemoryGetMappedMipmappedArray)", __FILE__, __LINE__);
  }
  mipmapped_ = mipmapped;
  cudaArray_t level;
  cudaResourceDesc resource{};
  status = cudaGetMipmappedArrayLevel(&level, mipmapped, 0);
  if (status == cudaSuccess) {
    resource.resType = cudaResourceTypeArray;
    resource.res.array.array = level;
    cudaSurfaceObject_t surface = 0;
    status = cudaCreateSurfaceObject(&surface, &resource);
    surface_ = surface;
  }
  if (status != cudaSuccess) {
    cudaFreeMipmappedArray(mipmapped);
    cudaDestroyExternalMemory(memory);
    mipmapped_ = memory_ = nullptr;
    throwCudaError(status, "a surface on a Vulkan image (cudaCreateSurfaceObject)", __FILE__, __LINE__);
  }
}

SharedSurface::~SharedSurface() {
  if (surface_) cudaDestroySurfaceObject(surface_);
  if (mipmapped_) cudaFreeMipmappedArray(static_cast<cudaMipmappedArray_t>(mipmapped_));
  if (memory_) cudaDestroyExternalMemory(static_cast<cudaExternalMemory_t>(memory_));
}

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
  cudaExternalMemory_t memory = importVulkanMemory(fd, allocationBytes, "importing a Vulkan buffer (cudaImportExternalMemory)");
  memory_ = memory;
  cudaExternalMemoryBufferDesc buffer{};
  buffer.offset = 0;
  buffer.size = usedBytes;
  cudaError_t status = cudaExternalMemoryGetMappedBuffer(&data_, memory, &buffer);
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

void SharedSemaphore::wait(void* stream) {
  cudaExternalSemaphoreWaitParams params{};
  cudaExternalSemaphore_t semaphore = static_cast<cudaExternalSemaphore_t>(semaphore_);
  PVR_CUDA_CHECK(cudaWaitExternalSemaphoresAsync(&semaphore, &params, 1, static_cast<cudaStream_t>(stream)));
}

HandOverEvents::HandOverEvents() {
  cudaEvent_t a, b;
  PVR_CUDA_CHECK(cudaEventCreate(&a));
  PVR_CUDA_CHECK(cudaEventCreate(&b));
  start_ = a, stop_ = b;
}

HandOverEvents::~HandOverEvents() {
  cudaEventDestroy(static_cast<cudaEvent_t>(start_));
  cudaEventDestroy(static_cast<cudaEvent_t>(stop_));
}

void HandOverEvents::begin(void* stream) {
  PVR_CUDA_CHECK(cudaEventRecord(static_cast<cudaEvent_t>(start_), static_cast<cudaStream_t>(stream)));
}

void HandOverEvents::end(void* stream) {
  PVR_CUDA_CHECK(cudaEventRecord(static_cast<cudaEvent_t>(stop_), static_cast<cudaStream_t>(stream)));
  recorded_ = true;
}

double HandOverEvents::lastMs() {
  if (!recorded_) return 0.0;
  float ms = 0;
  PVR_CUDA_CHECK(cudaEventSynchronize(static_cast<cudaEvent_t>(stop_)));
  PVR_CUDA_CHECK(cudaEventElapsedTime(&ms, static_cast<cudaEvent_t>(start_), static_cast<cudaEvent_t>(stop_)));
  return ms;
}

void synchronizeStream(void* stream) { PVR_CUDA_CHECK(cudaStreamSynchronize(static_cast<cudaStream_t>(stream))); }

void synchronizeStreamQuietly(void* stream) noexcept {
  if (cudaStreamSynchronize(static_cast<cudaStream_t>(stream)) != cudaSuccess) cudaGetLastError();
}

void encodeEyeForDisplay(const Vec3* image, const float* inverseDepth, size_t pixels, float exposure,
                         DisplayEncoding encoding, float nearZ, void* colour, float* depth, void* stream) {
  if (!pixels) return;
  const int block = 256;
  launch("display hand-over encode", encodeEyeKernel, dim3(unsigned((pixels + block - 1) / block)), dim3(block), 0,
         static_cast<cudaStream_t>(stream), image, inverseDepth, pixels, exposure, encoding, nearZ,
         static_cast<unsigned char*>(colour), depth);
}

void encodeEyeToSurface(const Vec3* image, const float* inverseDepth, int width, int height, float exposure,
                        DisplayEncoding encoding, float nearZ, unsigned long long surface, float* depth, void* stream) {
  if (width <= 0 || height <= 0) return;
  dim3 block(32, 8);
  dim3 grid(unsigned((width + 31) / 32), unsigned((height + 7) / 8));
  launch("display hand-over encode (image)", encodeEyeSurfaceKernel, grid, block, 0, static_cast<cudaStream_t>(stream), image,
         inverseDepth, width, height, exposure, encoding, nearZ, cudaSurfaceObject_t(surface), depth);
}

}  // namespace pvr::cuda
