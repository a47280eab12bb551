#include "pvr/vulkan/vulkan_context.h"

#include <algorithm>
#include <cstring>

#include "pvr/util/error.h"
#include "pvr/util/fault_injection.h"

namespace pvr {

const char* vkResultName(VkResult r) {
  switch (r) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_NOT_READY: return "VK_NOT_READY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_SUBOPTIMAL_KHR: return "VK_SUBOPTIMAL_KHR";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_MEMORY_MAP_FAILED: return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_FORMAT_NOT_SUPPORTED: return "VK_ERROR_FORMAT_NOT_SUPPORTED";
    case VK_ERROR_SURFACE_LOST_KHR: return "VK_ERROR_SURFACE_LOST_KHR";
    case VK_ERROR_NATIVE_WINDOW_IN_USE_KHR: return "VK_ERROR_NATIVE_WINDOW_IN_USE_KHR";
    case VK_ERROR_OUT_OF_DATE_KHR: return "VK_ERROR_OUT_OF_DATE_KHR";
    case VK_ERROR_INVALID_EXTERNAL_HANDLE: return "VK_ERROR_INVALID_EXTERNAL_HANDLE";
    default: return "VkResult error";
  }
}

void vkCheck(VkResult result, const char* what) {
  if (result == VK_ERROR_DEVICE_LOST)
    throw Error(std::string("Vulkan: ") + what + " failed (VK_ERROR_DEVICE_LOST): the GPU device was lost; photonvr cannot continue on it");
  if (result != VK_SUCCESS) throw Error(std::string("Vulkan: ") + what + " failed (" + vkResultName(result) + ")");
}

VkResult queueSubmit(VkQueue queue, uint32_t count, const VkSubmitInfo* submits, VkFence fence) {
  // An injected loss is a submission that failed: none of its work runs, its fence and semaphores
  // are never signalled, as after a real loss.
  if (faultInjected(Fault::VulkanDeviceLost)) return VK_ERROR_DEVICE_LOST;
  return vkQueueSubmit(queue, count, submits, fence);
}

namespace {

bool hasExtension(const std::vector<VkExtensionProperties>& list, const char* name) {
  return std::any_of(list.begin(), list.end(), [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

std::vector<VkExtensionProperties> deviceExtensions(VkPhysicalDevice physical) {
  uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(physical, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> list(n);
  vkEnumerateDeviceExtensionProperties(physical, nullptr, &n, list.data());
  return list;
}

int deviceRank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
  }
}

}  // namespace

VulkanContext::VulkanContext(const VulkanContextOptions& options) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "photonvr";
  app.applicationVersion = VK_MAKE_VERSION(0, 1, 0);
  app.pEngineName = "photonvr";
  app.apiVersion = options.apiVersion;
  std::vector<const char*> instanceExtensions = options.instanceExtensions;
  std::vector<const char*> layers;
  if (options.validation) {
    uint32_t n = 0;
    vkEnumerateInstanceLayerProperties(&n, nullptr);
    std::vector<VkLayerProperties> available(n);
    vkEnumerateInstanceLayerProperties(&n, available.data());
    for (const VkLayerProperties& l : available)
      if (std::strcmp(l.layerName, "VK_LAYER_KHRONOS_validation") == 0) layers.push_back("VK_LAYER_KHRONOS_validation");
  }
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  ici.enabledExtensionCount = uint32_t(instanceExtensions.size());
  ici.ppEnabledExtensionNames = instanceExtensions.data();
  ici.enabledLayerCount = uint32_t(layers.size());
  ici.ppEnabledLayerNames = layers.data();
  if (options.hooks.createInstance) {
    instance_ = options.hooks.createInstance(ici);
  } else {
    VkResult r = vkCreateInstance(&ici, nullptr, &instance_);
    if (r == VK_ERROR_INCOMPATIBLE_DRIVER || r == VK_ERROR_INITIALIZATION_FAILED)
      throw Error(std::string("no Vulkan driver found (") + vkResultName(r) +
                  "): install one (mesa-vulkan-drivers for the CPU, or the GPU vendor's)");
    if (r == VK_ERROR_EXTENSION_NOT_PRESENT)
      throw Error("the Vulkan driver lacks an instance extension photonvr needs (a window surface?)");
    vkCheck(r, "vkCreateInstance");
  }
  try {
    if (options.hooks.pickPhysicalDevice) {
      physical_ = options.hooks.pickPhysicalDevice(instance_);
    } else {
      uint32_t n = 0;
      vkEnumeratePhysicalDevices(instance_, &n, nullptr);
      std::vector<VkPhysicalDevice> devices(n);
      vkEnumeratePhysicalDevices(instance_, &n, devices.data());
      if (devices.empty()) throw Error("no Vulkan device found (no GPU driver and no lavapipe: install mesa-vulkan-drivers)");
      int best = 1 << 30;
      for (VkPhysicalDevice d : devices) {
        VkPhysicalDeviceIDProperties id{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES};
        VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
        props.pNext = &id;
        vkGetPhysicalDeviceProperties2(d, &props);
        int rank = deviceRank(props.properties.deviceType);
        if (options.hasPreferredUuid && std::memcmp(id.deviceUUID, options.preferredUuid, 16) == 0) rank = -1;
        if (rank < best) best = rank, physical_ = d;
      }
    }
    VkPhysicalDeviceIDProperties id{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES};
    VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    props.pNext = &id;
    vkGetPhysicalDeviceProperties2(physical_, &props);
    deviceName_ = props.properties.deviceName;
    cpuDevice_ = props.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    std::memcpy(uuid_, id.deviceUUID, 16);

    uint32_t familyCount = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &familyCount, nullptr);
    std::vector<VkQueueFamilyProperties> families(familyCount);
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &familyCount, families.data());
    bool found = false;
    for (uint32_t f = 0; f < familyCount && !found; ++f)
      if ((families[f].queueFlags & VK_QUEUE_GRAPHICS_BIT) && (!options.queueFamilyFilter || options.queueFamilyFilter(physical_, f)))
        queueFamily_ = f, found = true;
    if (!found) throw Error("the Vulkan device '" + deviceName_ + "' has no graphics queue that can present here");

    std::vector<VkExtensionProperties> available = deviceExtensions(physical_);
    std::vector<const char*> extensions = options.deviceExtensions;
    for (const char* e : extensions)
      if (!hasExtension(available, e)) throw Error("the Vulkan device '" + deviceName_ + "' lacks the extension " + e);
    externalFd_ = hasExtension(available, VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME) &&
                  hasExtension(available, VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME) && !cpuDevice_;
    if (externalFd_) {
      extensions.push_back(VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME);
      extensions.push_back(VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME);
    }
    VkPhysicalDeviceMultiviewFeatures multiview{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MULTIVIEW_FEATURES};
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    features.pNext = &multiview;
    vkGetPhysicalDeviceFeatures2(physical_, &features);
    multiview_ = multiview.multiview == VK_TRUE;
    VkPhysicalDeviceMultiviewFeatures enabledMultiview{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MULTIVIEW_FEATURES};
    enabledMultiview.multiview = VK_TRUE;
    float priority = 1.0f;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = queueFamily_;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    if (multiview_) dci.pNext = &enabledMultiview;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    dci.enabledExtensionCount = uint32_t(extensions.size());
    dci.ppEnabledExtensionNames = extensions.data();
    if (options.hooks.createDevice) device_ = options.hooks.createDevice(physical_, dci);
    else vkCheck(vkCreateDevice(physical_, &dci, nullptr, &device_), "vkCreateDevice");
    vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = queueFamily_;
    vkCheck(vkCreateCommandPool(device_, &pci, nullptr, &pool_), "vkCreateCommandPool");
  } catch (...) {
    if (device_) vkDestroyDevice(device_, nullptr);
    vkDestroyInstance(instance_, nullptr);
    throw;
  }
}

VulkanContext::~VulkanContext() {
  if (device_) {
    vkDeviceWaitIdle(device_);
    vkDestroyCommandPool(device_, pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
}

uint32_t VulkanContext::memoryType(uint32_t typeBits, VkMemoryPropertyFlags flags) const {
  VkPhysicalDeviceMemoryProperties memory;
  vkGetPhysicalDeviceMemoryProperties(physical_, &memory);
  for (uint32_t i = 0; i < memory.memoryTypeCount; ++i)
    if ((typeBits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & flags) == flags) return i;
  throw Error("the Vulkan device '" + deviceName_ + "' has no memory of the kind photonvr needs");
}

void VulkanContext::runOnce(const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = pool_;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cmd;
  vkCheck(vkAllocateCommandBuffers(device_, &ai, &cmd), "vkAllocateCommandBuffers");
  VkFence fence = VK_NULL_HANDLE;
  try {
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    vkCheck(vkBeginCommandBuffer(cmd, &bi), "vkBeginCommandBuffer");
    record(cmd);
    vkCheck(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    vkCheck(vkCreateFence(device_, &fci, nullptr, &fence), "vkCreateFence");
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    vkCheck(queueSubmit(queue_, 1, &si, fence), "vkQueueSubmit");
    VkResult r = vkWaitForFences(device_, 1, &fence, VK_TRUE, 10'000'000'000ull);
    if (r == VK_TIMEOUT) throw Error("Vulkan: the GPU did not finish a copy within 10 s");
    vkCheck(r, "vkWaitForFences");
  } catch (...) {
    if (fence) vkDestroyFence(device_, fence, nullptr);
    vkFreeCommandBuffers(device_, pool_, 1, &cmd);
    throw;
  }
  vkDestroyFence(device_, fence, nullptr);
  vkFreeCommandBuffers(device_, pool_, 1, &cmd);
}

VulkanBuffer& VulkanBuffer::operator=(VulkanBuffer&& o) noexcept {
  std::swap(device, o.device);
  std::swap(buffer, o.buffer);
  std::swap(memory, o.memory);
  std::swap(size, o.size);
  std::swap(allocationSize, o.allocationSize);
  std::swap(mapped, o.mapped);
  return *this;
}

VulkanBuffer::~VulkanBuffer() {
  if (!device) return;
  if (buffer) vkDestroyBuffer(device, buffer, nullptr);
  if (memory) vkFreeMemory(device, memory, nullptr);
}

namespace {

// Memory for one buffer or image. Exportable memory is a dedicated allocation exported as an
// opaque fd (CUDA imports it as dedicated).
VkDeviceMemory allocate(const VulkanContext& vk, const VkMemoryRequirements& req, VkMemoryPropertyFlags properties,
                        bool exportable, VkBuffer buffer, VkImage image, const char* what) {
  VkMemoryDedicatedAllocateInfo dedicated{VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO};
  dedicated.buffer = buffer;
  dedicated.image = image;
  VkExportMemoryAllocateInfo exportInfo{VK_STRUCTURE_TYPE_EXPORT_MEMORY_ALLOCATE_INFO};
  exportInfo.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  exportInfo.pNext = &dedicated;
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.pNext = exportable ? &exportInfo : nullptr;
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = vk.memoryType(req.memoryTypeBits, properties);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkResult r = faultInjected(Fault::VulkanAllocation) ? VK_ERROR_OUT_OF_DEVICE_MEMORY
                                                      : vkAllocateMemory(vk.device(), &mai, nullptr, &memory);
  if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
    throw Error("Vulkan: out of memory for a " + std::to_string((req.size + 1023) >> 10) + " KiB " + what);
  vkCheck(r, "vkAllocateMemory");
  return memory;
}

enum class BufferKind { Host, Device, Exportable };

VulkanBuffer makeBuffer(const VulkanContext& vk, VkDeviceSize size, VkBufferUsageFlags usage, BufferKind kind) {
  const bool exportable = kind == BufferKind::Exportable;
  VulkanBuffer b;
  b.device = vk.device();
  b.size = size;
  VkExternalMemoryBufferCreateInfo external{VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO};
  external.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.pNext = exportable ? &external : nullptr;
  bci.size = size;
  bci.usage = usage;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  vkCheck(vkCreateBuffer(b.device, &bci, nullptr, &b.buffer), "vkCreateBuffer");
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(b.device, b.buffer, &req);
  b.memory = allocate(vk, req, kind != BufferKind::Host ? VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT
                                                       : VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                      exportable, b.buffer, VK_NULL_HANDLE, "buffer");
  b.allocationSize = req.size;
  vkCheck(vkBindBufferMemory(b.device, b.buffer, b.memory, 0), "vkBindBufferMemory");
  if (kind == BufferKind::Host) vkCheck(vkMapMemory(b.device, b.memory, 0, size, 0, &b.mapped), "vkMapMemory");
  return b;
}

}  // namespace

VulkanBuffer makeHostBuffer(const VulkanContext& vk, VkDeviceSize size, VkBufferUsageFlags usage) {
  return makeBuffer(vk, size, usage, BufferKind::Host);
}

VulkanBuffer makeDeviceBuffer(const VulkanContext& vk, VkDeviceSize size, VkBufferUsageFlags usage) {
  return makeBuffer(vk, size, usage, BufferKind::Device);
}

VulkanBuffer makeExportableBuffer(const VulkanContext& vk, VkDeviceSize size, VkBufferUsageFlags usage) {
  if (!vk.canShareWithCuda()) throw Error("the Vulkan device '" + vk.deviceName() + "' cannot share memory with CUDA");
  return makeBuffer(vk, size, usage, BufferKind::Exportable);
}

VulkanImage& VulkanImage::operator=(VulkanImage&& o) noexcept {
  std::swap(device, o.device);
  std::swap(image, o.image);
  std::swap(memory, o.memory);
  std::swap(format, o.format);
  std::swap(width, o.width);
  std::swap(height, o.height);
  std::swap(layers, o.layers);
  std::swap(allocationSize, o.allocationSize);
  return *this;
}

VulkanImage::~VulkanImage() {
  if (!device) return;
  if (image) vkDestroyImage(device, image, nullptr);
  if (memory) vkFreeMemory(device, memory, nullptr);
}

namespace {

VulkanImage createImage(const VulkanContext& vk, int width, int height, VkFormat format, VkImageUsageFlags usage,
                        bool exportable, int layers) {
  VulkanImage img;
  img.device = vk.device();
  img.format = format;
  img.width = width, img.height = height, img.layers = layers;
  VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ici.imageType = VK_IMAGE_TYPE_2D;
  ici.format = format;
  ici.extent = {uint32_t(width), uint32_t(height), 1};
  ici.mipLevels = 1;
  ici.arrayLayers = uint32_t(layers);
  ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL;
  ici.usage = usage;
  ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkExternalMemoryImageCreateInfo external{VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_IMAGE_CREATE_INFO};
  external.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  if (exportable) ici.pNext = &external;
  vkCheck(vkCreateImage(img.device, &ici, nullptr, &img.image), "vkCreateImage");
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(img.device, img.image, &req);
  img.memory = allocate(vk, req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, exportable, VK_NULL_HANDLE, img.image, "image");
  img.allocationSize = req.size;
  vkCheck(vkBindImageMemory(img.device, img.image, img.memory, 0), "vkBindImageMemory");
  return img;
}

}  // namespace

VulkanImage makeImage(const VulkanContext& vk, int width, int height, VkFormat format, VkImageUsageFlags usage,
                      int layers) {
  return createImage(vk, width, height, format, usage, false, layers);
}

VulkanImage makeExportableImage(const VulkanContext& vk, int width, int height, VkFormat format, VkImageUsageFlags usage) {
  if (!vk.canShareWithCuda()) throw Error("the Vulkan device '" + vk.deviceName() + "' cannot share memory with CUDA");
  return createImage(vk, width, height, format, usage, true, 1);
}

void transitionImage(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, VkImageLayout from, VkImageLayout to) {
  VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  b.srcAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {aspect, 0, 1, 0, 1};
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0,
                       nullptr, 1, &b);
}

std::vector<unsigned char> readImage(VulkanContext& vk, VkImage image, VkImageAspectFlags aspect, int width, int height,
                                     int bytesPerPixel, VkImageLayout layout) {
  const VkDeviceSize bytes = VkDeviceSize(width) * height * bytesPerPixel;
  VulkanBuffer staging = makeHostBuffer(vk, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  vk.runOnce([&](VkCommandBuffer cmd) {
    transitionImage(cmd, image, aspect, layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    VkBufferImageCopy region{};
    region.imageSubresource = {aspect, 0, 0, 1};
    region.imageExtent = {uint32_t(width), uint32_t(height), 1};
    vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.buffer, 1, &region);
    VkMemoryBarrier toHost{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    toHost.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &toHost, 0, nullptr, 0, nullptr);
    transitionImage(cmd, image, aspect, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, layout);
  });
  const unsigned char* p = static_cast<const unsigned char*>(staging.mapped);
  return std::vector<unsigned char>(p, p + bytes);
}

}  // namespace pvr
