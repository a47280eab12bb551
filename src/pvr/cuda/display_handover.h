#pragma once
// The CUDA side of handing eye images to a display without a host round trip: Vulkan memory and
// semaphores exported as file descriptors, imported here (cudaImportExternalMemory /
// cudaImportExternalSemaphore), and the kernel that encodes an eye's linear image and depth into
// that memory in the display's format (image/display_encoding.h). A plain C++ header.
#include <cstddef>
#include <cstdint>
#include <memory>

#include "pvr/image/display_encoding.h"

namespace pvr::cuda {

// The UUID of the current CUDA device (to find the same GPU in Vulkan); false without a GPU.
bool currentDeviceUuid(uint8_t uuid[16]);

// A Vulkan allocation mapped into CUDA. Takes ownership of `fd` (CUDA closes it).
class SharedBuffer {
 public:
  SharedBuffer(int fd, size_t allocationBytes, size_t usedBytes);
  ~SharedBuffer();
  SharedBuffer(const SharedBuffer&) = delete;
  SharedBuffer& operator=(const SharedBuffer&) = delete;
  void* data() const { return data_; }

 private:
  void* memory_ = nullptr;  // cudaExternalMemory_t
  void* data_ = nullptr;
};

// A Vulkan image (optimal tiling, one level) mapped into CUDA as a surface it writes texels to.
// Takes ownership of `fd`. bytesPerPixel 4 (8-bit RGBA) or 8 (half RGBA).
class SharedSurface {
 public:
  SharedSurface(int fd, size_t allocationBytes, int width, int height, int bytesPerPixel);
  ~SharedSurface();
  SharedSurface(const SharedSurface&) = delete;
  SharedSurface& operator=(const SharedSurface&) = delete;
  unsigned long long surface() const { return surface_; }  // cudaSurfaceObject_t

 private:
  void* memory_ = nullptr;     // cudaExternalMemory_t
  void* mipmapped_ = nullptr;  // cudaMipmappedArray_t
  unsigned long long surface_ = 0;
};

// A Vulkan (binary) semaphore that CUDA signals when its work on a stream is done, or that CUDA's
// later work on a stream waits for (Vulkan signals it).
class SharedSemaphore {
 public:
  explicit SharedSemaphore(int fd);
  ~SharedSemaphore();
  SharedSemaphore(const SharedSemaphore&) = delete;
  SharedSemaphore& operator=(const SharedSemaphore&) = delete;
  void signal(void* stream);  // cudaStream_t
  void wait(void* stream);    // cudaStream_t

 private:
  void* semaphore_ = nullptr;  // cudaExternalSemaphore_t
};

// Timing events around the hand-over's kernels, recorded on the stream they run on.
class HandOverEvents {
 public:
  HandOverEvents();
  ~HandOverEvents();
  HandOverEvents(const HandOverEvents&) = delete;
  HandOverEvents& operator=(const HandOverEvents&) = delete;
  void begin(void* stream);  ///< cudaStream_t
  void end(void* stream);
  bool recorded() const { return recorded_; }
  double lastMs();           ///< GPU time between the last begin and end (waits for end)

 private:
  void* start_ = nullptr;
  void* stop_ = nullptr;
  bool recorded_ = false;
};

// Waits for all work on a stream (cudaStream_t; null: the default stream).
void synchronizeStream(void* stream);
void synchronizeStreamQuietly(void* stream) noexcept;  ///< for destructors: errors are dropped

// Encodes `pixels` of a linear image into `colour` (displayBytesPerPixel each) and, when both are
// given, 1 / view depth into reversed-Z depth floats at `depth`. Asynchronous on `stream`.
void encodeEyeForDisplay(const Vec3* image, const float* inverseDepth, size_t pixels, float exposure,
                         DisplayEncoding encoding, float nearZ, void* colour, float* depth, void* stream);

// As encodeEyeForDisplay, the colour written as texels of a shared image's surface.
void encodeEyeToSurface(const Vec3* image, const float* inverseDepth, int width, int height, float exposure,
                        DisplayEncoding encoding, float nearZ, unsigned long long surface, float* depth, void* stream);

}  // namespace pvr::cuda
