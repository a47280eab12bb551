#pragma once
// The eye images' way into Vulkan images (a headset's swapchain images, the viewer's eye images):
// each eye is encoded in the display's format (image/display_encoding.h) into a staging buffer
// and copied into its target on the queue. The CPU backend's images are encoded on the host into
// mapped memory; the CUDA backend's are encoded by a kernel straight into device-local Vulkan
// memory that CUDA imported (VK_KHR_external_memory_fd), and the copy waits for the kernel on
// a shared semaphore: no host round trip. Buffers are double-buffered; a slot is reused only once
// the GPU finished its previous copy.
#include <memory>
#include <string>
#include <vector>

#include "pvr/image/display_encoding.h"
#include "pvr/image/image.h"
#include "pvr/vulkan/vulkan_context.h"

namespace pvr {

enum class HandOverPath : int {
  HostStaging = 0,  ///< host images encoded into mapped memory (CPU backend, or no CUDA sharing)
  CudaShared = 1,   ///< GPU images encoded by CUDA into Vulkan memory it imported
};
const char* handOverPathName(HandOverPath path);

// An eye's pictures: the host images, or the CUDA backend's device buffers.
struct EyeSource {
  const Image* image = nullptr;
  const std::vector<float>* inverseDepth = nullptr;
  const Vec3* deviceImage = nullptr;
  const float* deviceInverseDepth = nullptr;
  void* deviceStream = nullptr;  ///< the stream that wrote the device buffers (Renderer::deviceStream): the encode runs on it
  bool present() const { return image || deviceImage; }
};

// Where an eye goes; each image is in its layout before the copy and is left in it after.
struct EyeTarget {
  VkImage colour = VK_NULL_HANDLE;
  VkImageLayout colourLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  VkImage depth = VK_NULL_HANDLE;  ///< D32_SFLOAT; none: no depth copied
  VkImageLayout depthLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
};

struct EyeTransferOptions {
  int width = 0, height = 0;            ///< per eye
  DisplayEncoding encoding = DisplayEncoding::Rgba8Srgb;
  bool depth = false;                   ///< also hand over reversed-Z depth
  float nearZ = 0.05f;                  ///< metres of depth 1 (display_encoding.h)
  float exposure = 1.0f;
  HandOverPath path = HandOverPath::HostStaging;
  bool colourViaImage = false;          ///< CudaShared: colour through a shared image, not a buffer
};

struct HandOverTiming {
  double encodeMs = 0;  ///< CUDA kernel time (0 on the host path: see hostEncodeMs)
  double copyMs = 0;    ///< Vulkan copy time on the queue (timestamps)
  double hostEncodeMs = 0;
};

// The colour format's encoding, or false for a format photonvr does not write.
bool encodingOfFormat(VkFormat format, DisplayEncoding& encoding);

class EyeTransfer {
 public:
  // Throws pvr::Error: CudaShared needs a device that shares memory with CUDA (canShareWithCuda).
  EyeTransfer(VulkanContext& vk, const EyeTransferOptions& options);
  ~EyeTransfer();
  EyeTransfer(const EyeTransfer&) = delete;
  EyeTransfer& operator=(const EyeTransfer&) = delete;

  // Encodes the eyes that have a source and submits their copies into the targets; later work on
  // the queue sees them. `signal`, if given, is signalled when the copies are done.
  void handOver(const EyeSource source[2], const EyeTarget target[2], VkSemaphore signal = VK_NULL_HANDLE);
  // Waits for the last hand-over and gives its GPU times.
  HandOverTiming lastTiming();
  void waitIdle();
  const EyeTransferOptions& options() const { return options_; }
  void setExposure(float exposure) { options_.exposure = exposure; }
  std::string describe() const;  ///< the path, and on CUDA whether colour goes through an image or a buffer

 private:
  struct Slot;
  VulkanContext& vk_;
  EyeTransferOptions options_;
  std::vector<std::unique_ptr<Slot>> slots_;
  size_t next_ = 0, last_ = 0;
  VkQueryPool timestamps_ = VK_NULL_HANDLE;
  double timestampPeriodNs_ = 1.0;
  bool timestampsValid_ = false;
  struct CudaState;
  void build();
  std::unique_ptr<CudaState> cuda_;
  double lastHostEncodeMs_ = 0;
  void* lastStream_ = nullptr;
  void release();
  bool sharedImages_ = false;
};

}  // namespace pvr
