#pragma once
// photonvr's Vulkan layer: one instance, device and queue, made by photonvr (the viewer, tests on
// lavapipe) or through an OpenXR runtime (which adds what its compositor needs and picks the
// physical device). The eye images reach displays through it (eye_transfer.h).
#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace pvr {

// Throws pvr::Error "Vulkan: <what> failed (VK_ERROR_...)" unless result is VK_SUCCESS.
void vkCheck(VkResult result, const char* what);
// vkQueueSubmit, every submission of photonvr goes through it (PVR_INJECT_FAULT=vk-device-lost:N
// makes the Nth answer VK_ERROR_DEVICE_LOST).
VkResult queueSubmit(VkQueue queue, uint32_t count, const VkSubmitInfo* submits, VkFence fence);
const char* vkResultName(VkResult result);

// How the instance and device are made: directly, or by someone else (OpenXR's
// xrCreateVulkanInstanceKHR / xrGetVulkanGraphicsDevice2KHR / xrCreateVulkanDeviceKHR).
struct VulkanCreateHooks {
  std::function<VkInstance(const VkInstanceCreateInfo&)> createInstance;           ///< default: vkCreateInstance
  std::function<VkPhysicalDevice(VkInstance)> pickPhysicalDevice;                  ///< default: see VulkanContextOptions
  std::function<VkDevice(VkPhysicalDevice, const VkDeviceCreateInfo&)> createDevice;  ///< default: vkCreateDevice
};

struct VulkanContextOptions {
  std::vector<const char*> instanceExtensions;  ///< required (e.g. GLFW's surface extensions)
  std::vector<const char*> deviceExtensions;    ///< required (e.g. VK_KHR_swapchain)
  bool validation = false;                      ///< VK_LAYER_KHRONOS_validation when installed
  // The physical device: the one with this UUID (the CUDA GPU) if any, else a discrete GPU,
  // else an integrated one, else a CPU device (lavapipe).
  bool hasPreferredUuid = false;
  uint8_t preferredUuid[16] = {};
  // A queue family must pass this too (the viewer: it can present to the window's surface).
  std::function<bool(VkPhysicalDevice, uint32_t family)> queueFamilyFilter;
  VulkanCreateHooks hooks;
  uint32_t apiVersion = VK_API_VERSION_1_1;
};

class VulkanContext {
 public:
  // Throws pvr::Error with one line naming the cause: no Vulkan loader or driver, no device,
  // a missing required extension.
  explicit VulkanContext(const VulkanContextOptions& options);
  ~VulkanContext();
  VulkanContext(const VulkanContext&) = delete;
  VulkanContext& operator=(const VulkanContext&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physicalDevice() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queueFamily() const { return queueFamily_; }
  VkCommandPool commandPool() const { return pool_; }
  const std::string& deviceName() const { return deviceName_; }
  bool isCpuDevice() const { return cpuDevice_; }  ///< lavapipe / llvmpipe
  const uint8_t* deviceUuid() const { return uuid_; }
  // VK_KHR_external_memory_fd and VK_KHR_external_semaphore_fd are enabled: CUDA can share memory.
  bool canShareWithCuda() const { return externalFd_; }
  // Multiview (both eyes in one render pass: the G-buffer pre-pass) is enabled where the device has it.
  bool hasMultiview() const { return multiview_; }

  // A memory type with these bits among `typeBits`; throws if there is none.
  uint32_t memoryType(uint32_t typeBits, VkMemoryPropertyFlags flags) const;
  // Records commands into a one-time command buffer, submits them and waits (at most 10 s).
  void runOnce(const std::function<void(VkCommandBuffer)>& record);

 private:
  VkInstance instance_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  uint32_t queueFamily_ = 0;
  std::string deviceName_;
  bool cpuDevice_ = false, externalFd_ = false, multiview_ = false;
  uint8_t uuid_[16] = {};
};

// A buffer with its memory, or an image with its memory (destroyed with the object).
struct VulkanBuffer {
  VkDevice device = VK_NULL_HANDLE;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize size = 0, allocationSize = 0;
  void* mapped = nullptr;  ///< host-visible buffers: mapped for their lifetime
  VulkanBuffer() = default;
  VulkanBuffer(VulkanBuffer&& other) noexcept { *this = std::move(other); }
  VulkanBuffer& operator=(VulkanBuffer&& other) noexcept;
  ~VulkanBuffer();
};
// Host-visible and coherent, mapped: the CPU writes, the GPU copies.
VulkanBuffer makeHostBuffer(const VulkanContext& vk, VkDeviceSize size, VkBufferUsageFlags usage);
// Device-local, for the GPU alone (filled by copies).
VulkanBuffer makeDeviceBuffer(const VulkanContext& vk, VkDeviceSize size, VkBufferUsageFlags usage);
// Device-local, exportable as an opaque file descriptor (CUDA imports it): needs canShareWithCuda.
VulkanBuffer makeExportableBuffer(const VulkanContext& vk, VkDeviceSize size, VkBufferUsageFlags usage);

struct VulkanImage {
  VkDevice device = VK_NULL_HANDLE;
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  int width = 0, height = 0, layers = 1;
  VkDeviceSize allocationSize = 0;
  VulkanImage() = default;
  VulkanImage(VulkanImage&& other) noexcept { *this = std::move(other); }
  VulkanImage& operator=(VulkanImage&& other) noexcept;
  ~VulkanImage();
};
// `layers` > 1: an array image (one layer per view of a multiview pass).
VulkanImage makeImage(const VulkanContext& vk, int width, int height, VkFormat format, VkImageUsageFlags usage,
                      int layers = 1);
// Device-local, optimal tiling, exportable as an opaque file descriptor (CUDA maps it as an array).
VulkanImage makeExportableImage(const VulkanContext& vk, int width, int height, VkFormat format, VkImageUsageFlags usage);

// Layout transition of a whole colour or depth image (all commands before, all after).
void transitionImage(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, VkImageLayout from, VkImageLayout to);
// Reads an image back to host bytes (tightly packed rows); the image is in `layout` and stays so.
std::vector<unsigned char> readImage(VulkanContext& vk, VkImage image, VkImageAspectFlags aspect, int width, int height,
                                     int bytesPerPixel, VkImageLayout layout);

}  // namespace pvr
