#include "pvr/vk/eye_transfer.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "pvr/util/error.h"
#include "pvr/util/parallel_for.h"
#ifdef PVR_HAVE_CUDA
#include "pvr/cuda/display_handover.h"
#endif

namespace pvr {

const char* handOverPathName(HandOverPath path) {
  return path == HandOverPath::CudaShared ? "CUDA to Vulkan, shared memory" : "host staging buffer";
}

std::string EyeTransfer::describe() const {
  if (options_.path != HandOverPath::CudaShared) return handOverPathName(options_.path);
  return sharedImages_ ? "CUDA to Vulkan, shared image (image-to-image copy)" : "CUDA to Vulkan, shared buffer (buffer-to-image copy)";
}

bool encodingOfFormat(VkFormat format, DisplayEncoding& encoding) {
  switch (format) {
    case VK_FORMAT_R8G8B8A8_SRGB: encoding = DisplayEncoding::Rgba8Srgb; return true;
    case VK_FORMAT_B8G8R8A8_SRGB: encoding = DisplayEncoding::Bgra8Srgb; return true;
    case VK_FORMAT_R8G8B8A8_UNORM: encoding = DisplayEncoding::Rgba8Linear; return true;
    case VK_FORMAT_B8G8R8A8_UNORM: encoding = DisplayEncoding::Bgra8Linear; return true;
    case VK_FORMAT_R16G16B16A16_SFLOAT: encoding = DisplayEncoding::Rgba16Float; return true;
    default: return false;
  }
}

struct EyeTransfer::Slot {
  VulkanBuffer colour[2], depth[2];
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  bool submitted = false;
  VulkanImage colourImage[2];  ///< CUDA shared path: the colour as an optimal-tiled image (image-to-image copy)
#ifdef PVR_HAVE_CUDA
  std::unique_ptr<cuda::SharedSurface> cudaSurface[2];
  std::unique_ptr<cuda::SharedBuffer> cudaColour[2], cudaDepth[2];
  std::unique_ptr<cuda::SharedSemaphore> encoded;
  std::unique_ptr<cuda::HandOverEvents> timing;
#endif
  VkSemaphore encodedSemaphore = VK_NULL_HANDLE;  ///< CUDA signals it, the copy waits on it
};

struct EyeTransfer::CudaState {
  PFN_vkGetMemoryFdKHR getMemoryFd = nullptr;
  PFN_vkGetSemaphoreFdKHR getSemaphoreFd = nullptr;
};

EyeTransfer::EyeTransfer(VulkanContext& vk, const EyeTransferOptions& options) : vk_(vk), options_(options) {
  try {
    build();
  } catch (...) {
    release();  // what was made before the failure
    throw;
  }
}

void EyeTransfer::build() {
  VulkanContext& vk = vk_;
  const EyeTransferOptions& options = options_;
  if (options.width <= 0 || options.height <= 0) throw Error("eye transfer: the eye size must be positive");
  const bool shared = options.path == HandOverPath::CudaShared;
#ifndef PVR_HAVE_CUDA
  if (shared) throw Error("this build of photonvr has no CUDA backend to share memory with Vulkan");
#endif
  if (shared && !vk.canShareWithCuda())
    throw Error("the Vulkan device '" + vk.deviceName() + "' cannot share memory with CUDA (VK_KHR_external_memory_fd)");
  if (shared) {
    cuda_ = std::make_unique<CudaState>();
    cuda_->getMemoryFd = reinterpret_cast<PFN_vkGetMemoryFdKHR>(vkGetDeviceProcAddr(vk.device(), "vkGetMemoryFdKHR"));
    cuda_->getSemaphoreFd = reinterpret_cast<PFN_vkGetSemaphoreFdKHR>(vkGetDeviceProcAddr(vk.device(), "vkGetSemaphoreFdKHR"));
    if (!cuda_->getMemoryFd || !cuda_->getSemaphoreFd) throw Error("the Vulkan driver does not export memory as file descriptors");
  }
  const size_t pixels = size_t(options.width) * options.height;
  const VkDeviceSize colourBytes = pixels * displayBytesPerPixel(options.encoding), depthBytes = pixels * sizeof(float);
  // Colour from CUDA into a buffer and a buffer-to-image copy, or (colourViaImage) into an
  // optimal-tiled image CUDA writes as a surface and an image-to-image copy; a driver that cannot
  // map images into CUDA falls back to buffers. On the H200 the buffer copy is the faster one
  // (0.23 against 0.36 ms for two 1440x1600 eyes: docs/xr.md).
  sharedImages_ = shared && options.colourViaImage;
  for (int s = 0; s < 2; ++s) {
    slots_.push_back(std::make_unique<Slot>());  // owned at once: release() cleans up after a failure
    Slot* slot = slots_.back().get();
    for (int e = 0; e < 2; ++e) {
      if (shared) {
#ifdef PVR_HAVE_CUDA
        if (sharedImages_) {
          try {
            const bool half = options.encoding == DisplayEncoding::Rgba16Float;
            slot->colourImage[e] = makeExportableImage(vk, options.width, options.height,
                                                       half ? VK_FORMAT_R16G16B16A16_SFLOAT : VK_FORMAT_R8G8B8A8_UNORM,
                                                       VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_STORAGE_BIT);
            VkMemoryGetFdInfoKHR info{VK_STRUCTURE_TYPE_MEMORY_GET_FD_INFO_KHR};
            info.memory = slot->colourImage[e].memory;
            info.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
            int fd = -1;
            vkCheck(cuda_->getMemoryFd(vk.device(), &info, &fd), "vkGetMemoryFdKHR (image)");
            slot->cudaSurface[e] = std::make_unique<cuda::SharedSurface>(fd, size_t(slot->colourImage[e].allocationSize), options.width,
                                                                         options.height, displayBytesPerPixel(options.encoding));
            VkImage image = slot->colourImage[e].image;
            vk.runOnce([&](VkCommandBuffer cmd) {  // GENERAL for good: CUDA writes it, Vulkan copies from it
              transitionImage(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
            });
          } catch (const Error& error) {
            std::fprintf(stderr, "photonvr: note: CUDA cannot write Vulkan images here (%s); colour goes through buffers\n", error.what());
            sharedImages_ = false;
            for (auto& old : slots_)
              for (int i = 0; i < 2; ++i) old->cudaSurface[i].reset(), old->colourImage[i] = VulkanImage();
          }
        }
#endif
        if (!sharedImages_) slot->colour[e] = makeExportableBuffer(vk, colourBytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
        if (options.depth) slot->depth[e] = makeExportableBuffer(vk, depthBytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
#ifdef PVR_HAVE_CUDA
        auto import = [&](const VulkanBuffer& b) {
          VkMemoryGetFdInfoKHR info{VK_STRUCTURE_TYPE_MEMORY_GET_FD_INFO_KHR};
          info.memory = b.memory;
          info.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
          int fd = -1;
          vkCheck(cuda_->getMemoryFd(vk.device(), &info, &fd), "vkGetMemoryFdKHR");
          return std::make_unique<cuda::SharedBuffer>(fd, size_t(b.allocationSize), size_t(b.size));
        };
        if (!sharedImages_) slot->cudaColour[e] = import(slot->colour[e]);
        if (options.depth) slot->cudaDepth[e] = import(slot->depth[e]);
#endif
      } else {
        slot->colour[e] = makeHostBuffer(vk, colourBytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
        if (options.depth) slot->depth[e] = makeHostBuffer(vk, depthBytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
      }
    }
    if (shared) {
      VkExportSemaphoreCreateInfo exportInfo{VK_STRUCTURE_TYPE_EXPORT_SEMAPHORE_CREATE_INFO};
      exportInfo.handleTypes = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
      VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
      sci.pNext = &exportInfo;
      vkCheck(vkCreateSemaphore(vk.device(), &sci, nullptr, &slot->encodedSemaphore), "vkCreateSemaphore");
#ifdef PVR_HAVE_CUDA
      VkSemaphoreGetFdInfoKHR info{VK_STRUCTURE_TYPE_SEMAPHORE_GET_FD_INFO_KHR};
      info.semaphore = slot->encodedSemaphore;
      info.handleType = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
      int fd = -1;
      vkCheck(cuda_->getSemaphoreFd(vk.device(), &info, &fd), "vkGetSemaphoreFdKHR");
      slot->encoded = std::make_unique<cuda::SharedSemaphore>(fd);
      slot->timing = std::make_unique<cuda::HandOverEvents>();
#endif
    }
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = vk.commandPool();
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    vkCheck(vkAllocateCommandBuffers(vk.device(), &ai, &slot->cmd), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    vkCheck(vkCreateFence(vk.device(), &fci, nullptr, &slot->fence), "vkCreateFence");
  }
#ifdef PVR_HAVE_CUDA
  if (shared && !sharedImages_)
    for (auto& slot : slots_)
      for (int e = 0; e < 2; ++e)
        if (!slot->colour[e].buffer) {
          slot->colour[e] = makeExportableBuffer(vk, colourBytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
          VkMemoryGetFdInfoKHR info{VK_STRUCTURE_TYPE_MEMORY_GET_FD_INFO_KHR};
          info.memory = slot->colour[e].memory;
          info.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
          int fd = -1;
          vkCheck(cuda_->getMemoryFd(vk.device(), &info, &fd), "vkGetMemoryFdKHR");
          slot->cudaColour[e] = std::make_unique<cuda::SharedBuffer>(fd, size_t(slot->colour[e].allocationSize), size_t(colourBytes));
        }
#endif
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(vk.physicalDevice(), &props);
  timestampPeriodNs_ = props.limits.timestampPeriod;
  if (props.limits.timestampComputeAndGraphics) {
    VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qci.queryCount = 4;
    vkCheck(vkCreateQueryPool(vk.device(), &qci, nullptr, &timestamps_), "vkCreateQueryPool");
  }
}

EyeTransfer::~EyeTransfer() { release(); }

void EyeTransfer::release() {
#ifdef PVR_HAVE_CUDA
  if (cuda_) cuda::synchronizeStreamQuietly(lastStream_);  // no kernel may still write the memory freed below
#endif
  vkDeviceWaitIdle(vk_.device());
  for (auto& slot : slots_) {
    if (slot->fence) vkDestroyFence(vk_.device(), slot->fence, nullptr);
    if (slot->cmd) vkFreeCommandBuffers(vk_.device(), vk_.commandPool(), 1, &slot->cmd);
#ifdef PVR_HAVE_CUDA
    slot->encoded.reset();
    for (int e = 0; e < 2; ++e) slot->cudaColour[e].reset(), slot->cudaDepth[e].reset(), slot->cudaSurface[e].reset();
#endif
    if (slot->encodedSemaphore) vkDestroySemaphore(vk_.device(), slot->encodedSemaphore, nullptr);
  }
  slots_.clear();
  if (timestamps_) vkDestroyQueryPool(vk_.device(), timestamps_, nullptr);
  timestamps_ = VK_NULL_HANDLE;
}

namespace {

void waitFence(VkDevice device, VkFence fence) {
  VkResult r = vkWaitForFences(device, 1, &fence, VK_TRUE, 5'000'000'000ull);
  if (r == VK_TIMEOUT) throw Error("Vulkan: the copy of an eye image did not finish within 5 s");
  vkCheck(r, "vkWaitForFences (eye copy)");
}

}  // namespace

void EyeTransfer::handOver(const EyeSource source[2], const EyeTarget target[2], VkSemaphore signal) {
  Slot& slot = *slots_[next_];
  const size_t slotIndex = next_;
  if (slot.submitted) {  // the GPU may still copy from this slot's buffers
    waitFence(vk_.device(), slot.fence);
    slot.submitted = false;
  }
  const size_t pixels = size_t(options_.width) * options_.height;
  const int bpp = displayBytesPerPixel(options_.encoding);
  bool anyCuda = false;
  [[maybe_unused]] void* stream = nullptr;  // the renderer's: its next frame cannot overwrite the images before the encode read them
  auto hostStart = std::chrono::steady_clock::now();
  for (int e = 0; e < 2; ++e) {
    const EyeSource& src = source[e];
    if (!src.present() || !target[e].colour) continue;
    if (src.deviceImage) {
#ifdef PVR_HAVE_CUDA
      if (!cuda_) throw Error("eye transfer: GPU images need the CUDA hand-over path");
      if (!anyCuda) {
        stream = src.deviceStream;
        lastStream_ = stream;
        slot.timing->begin(stream);
      }
      anyCuda = true;
      float* depth = options_.depth ? static_cast<float*>(slot.cudaDepth[e]->data()) : nullptr;
      if (sharedImages_)
        cuda::encodeEyeToSurface(src.deviceImage, options_.depth ? src.deviceInverseDepth : nullptr, options_.width,
                                 options_.height, options_.exposure, options_.encoding, options_.nearZ,
                                 slot.cudaSurface[e]->surface(), depth, stream);
      else
        cuda::encodeEyeForDisplay(src.deviceImage, options_.depth ? src.deviceInverseDepth : nullptr, pixels,
                                  options_.exposure, options_.encoding, options_.nearZ, slot.cudaColour[e]->data(), depth,
                                  stream);
#else
      throw Error("eye transfer: GPU images without a CUDA build");
#endif
      continue;
    }
    if (cuda_) throw Error("eye transfer: the CUDA hand-over path takes GPU images, not host images");
    const Image& image = *src.image;
    if (image.width != options_.width || image.height != options_.height)
      throw Error("eye transfer: the eye image is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                  ", the display's " + std::to_string(options_.width) + "x" + std::to_string(options_.height));
    unsigned char* colour = static_cast<unsigned char*>(slot.colour[e].mapped);
    float* depth = options_.depth ? static_cast<float*>(slot.depth[e].mapped) : nullptr;
    const std::vector<float>* inverseDepth = src.inverseDepth;
    const float exposure = options_.exposure, nearZ = options_.nearZ;
    const DisplayEncoding encoding = options_.encoding;
    parallelFor("display hand-over encode", pixels, 16384, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) {
        encodeDisplayPixel(image.pixels[i], exposure, encoding, colour + i * bpp);
        if (depth) depth[i] = inverseDepth && i < inverseDepth->size() ? reversedDepth((*inverseDepth)[i], nearZ) : 0.0f;
      }
    });
  }
  lastHostEncodeMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - hostStart).count();
#ifdef PVR_HAVE_CUDA
  if (anyCuda) {
    slot.timing->end(stream);
    slot.encoded->signal(stream);
  }
#endif

  VkCommandBuffer cmd = slot.cmd;
  vkCheck(vkResetCommandBuffer(cmd, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkCheck(vkBeginCommandBuffer(cmd, &bi), "vkBeginCommandBuffer");
  const uint32_t query = uint32_t(slotIndex) * 2;
  if (timestamps_) {
    vkCmdResetQueryPool(cmd, timestamps_, query, 2);
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, timestamps_, query);
  }
  // Memory CUDA wrote is acquired from the external queue family before the copies read it, and
  // released back after them (the external-memory ownership rules).
  std::vector<VkBufferMemoryBarrier> acquire, release;
  std::vector<VkImageMemoryBarrier> acquireImages, releaseImages;
  if (anyCuda) {
    for (int e = 0; e < 2; ++e) {
      if (!source[e].deviceImage || !target[e].colour) continue;
      auto buffer = [&](VkBuffer b, bool toUs) {
        VkBufferMemoryBarrier x{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
        x.srcAccessMask = toUs ? 0 : VK_ACCESS_TRANSFER_READ_BIT;
        x.dstAccessMask = toUs ? VK_ACCESS_TRANSFER_READ_BIT : 0;
        x.srcQueueFamilyIndex = toUs ? VK_QUEUE_FAMILY_EXTERNAL : vk_.queueFamily();
        x.dstQueueFamilyIndex = toUs ? vk_.queueFamily() : VK_QUEUE_FAMILY_EXTERNAL;
        x.buffer = b;
        x.size = VK_WHOLE_SIZE;
        return x;
      };
      if (slot.colour[e].buffer) acquire.push_back(buffer(slot.colour[e].buffer, true)), release.push_back(buffer(slot.colour[e].buffer, false));
      if (options_.depth && slot.depth[e].buffer)
        acquire.push_back(buffer(slot.depth[e].buffer, true)), release.push_back(buffer(slot.depth[e].buffer, false));
      if (slot.colourImage[e].image) {
        auto image = [&](bool toUs) {
          VkImageMemoryBarrier x{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
          x.srcAccessMask = toUs ? 0 : VK_ACCESS_TRANSFER_READ_BIT;
          x.dstAccessMask = toUs ? VK_ACCESS_TRANSFER_READ_BIT : 0;
          x.oldLayout = x.newLayout = VK_IMAGE_LAYOUT_GENERAL;
          x.srcQueueFamilyIndex = toUs ? VK_QUEUE_FAMILY_EXTERNAL : vk_.queueFamily();
          x.dstQueueFamilyIndex = toUs ? vk_.queueFamily() : VK_QUEUE_FAMILY_EXTERNAL;
          x.image = slot.colourImage[e].image;
          x.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
          return x;
        };
        acquireImages.push_back(image(true));
        releaseImages.push_back(image(false));
      }
    }
    if (!acquire.empty() || !acquireImages.empty())
      vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr,
                           uint32_t(acquire.size()), acquire.data(), uint32_t(acquireImages.size()), acquireImages.data());
  }
  for (int e = 0; e < 2; ++e) {
    if (!source[e].present() || !target[e].colour) continue;
    VkBufferImageCopy region{};
    region.imageExtent = {uint32_t(options_.width), uint32_t(options_.height), 1};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    // From UNDEFINED: every texel is overwritten, so the old contents need not be kept (on GPUs
    // with compressed surfaces keeping them costs a decompression per frame).
    transitionImage(cmd, target[e].colour, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    if (slot.colourImage[e].image) {
      VkImageCopy copy{};
      copy.srcSubresource = copy.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      copy.extent = region.imageExtent;
      vkCmdCopyImage(cmd, slot.colourImage[e].image, VK_IMAGE_LAYOUT_GENERAL, target[e].colour, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
    } else {
      vkCmdCopyBufferToImage(cmd, slot.colour[e].buffer, target[e].colour, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    }
    transitionImage(cmd, target[e].colour, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, target[e].colourLayout);
    if (options_.depth && target[e].depth) {
      region.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
      transitionImage(cmd, target[e].depth, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
      vkCmdCopyBufferToImage(cmd, slot.depth[e].buffer, target[e].depth, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
      transitionImage(cmd, target[e].depth, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, target[e].depthLayout);
    }
  }
  if (!release.empty() || !releaseImages.empty())
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0, nullptr,
                         uint32_t(release.size()), release.data(), uint32_t(releaseImages.size()), releaseImages.data());
  if (timestamps_) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, timestamps_, query + 1);
  vkCheck(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
  vkCheck(vkResetFences(vk_.device(), 1, &slot.fence), "vkResetFences");
  // The whole batch waits for CUDA's encode, the first timestamp included: the timestamps then
  // time the copies alone, not the wait for the kernel.
  VkPipelineStageFlags waitStage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  if (anyCuda) {
    si.waitSemaphoreCount = 1;
    si.pWaitSemaphores = &slot.encodedSemaphore;
    si.pWaitDstStageMask = &waitStage;
  }
  if (signal) {
    si.signalSemaphoreCount = 1;
    si.pSignalSemaphores = &signal;
  }
  vkCheck(queueSubmit(vk_.queue(), 1, &si, slot.fence), "vkQueueSubmit (eye copy)");
  slot.submitted = true;
  timestampsValid_ = timestamps_ != VK_NULL_HANDLE;
  last_ = slotIndex;
  next_ = (next_ + 1) % slots_.size();
}

HandOverTiming EyeTransfer::lastTiming() {
  HandOverTiming t;
  t.hostEncodeMs = lastHostEncodeMs_;
  Slot& slot = *slots_[last_];
  if (!slot.submitted) return t;
  waitFence(vk_.device(), slot.fence);
  if (timestampsValid_) {
    uint64_t ticks[2] = {0, 0};
    if (vkGetQueryPoolResults(vk_.device(), timestamps_, uint32_t(last_) * 2, 2, sizeof ticks, ticks, sizeof(uint64_t),
                              VK_QUERY_RESULT_64_BIT) == VK_SUCCESS)
      t.copyMs = double(ticks[1] - ticks[0]) * timestampPeriodNs_ * 1e-6;
  }
#ifdef PVR_HAVE_CUDA
  if (cuda_ && slot.timing && slot.timing->recorded()) t.encodeMs = slot.timing->lastMs();
#endif
  return t;
}

void EyeTransfer::waitIdle() {
#ifdef PVR_HAVE_CUDA
  if (cuda_) cuda::synchronizeStream(lastStream_);
#endif
  for (auto& slot : slots_)
    if (slot->submitted) waitFence(vk_.device(), slot->fence), slot->submitted = false;
}

}  // namespace pvr
