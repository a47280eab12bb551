// The CUDA -> Vulkan hand-over on a GPU: the CUDA backend's eye images, encoded by a kernel into
// Vulkan memory that CUDA imported and copied on the Vulkan queue after a shared semaphore,
// arrive in Vulkan images as the host encoding of the same images (to one code value: the
// device's powf may differ from the host's by an ulp at a rounding edge), and depth exactly.
// Skips without a GPU, or without a Vulkan driver on it that shares memory with CUDA.
#include <gtest/gtest.h>

#include <cstring>

#include "pvr/cuda/cuda_util.cuh"
#include "pvr/cuda/display_handover.h"
#include "pvr/render/renderer.h"
#include "pvr/scene/scene.h"
#include "pvr/util/error.h"
#include "pvr/vk/eye_transfer.h"

namespace pvr {
namespace {

TEST(GpuHandOver, CudaImagesArriveInVulkanWithoutTheHost) {
  std::string why;
  if (!cudaBackendAvailable(&why)) GTEST_SKIP() << "no GPU: " << why;
  VulkanContextOptions vo;
  vo.hasPreferredUuid = cuda::currentDeviceUuid(vo.preferredUuid);
  std::unique_ptr<VulkanContext> vk;
  try {
    vk = std::make_unique<VulkanContext>(vo);
  } catch (const Error& e) {
    GTEST_SKIP() << "no Vulkan: " << e.what();
  }
  if (!vk->canShareWithCuda() || std::memcmp(vk->deviceUuid(), vo.preferredUuid, 16) != 0)
    GTEST_SKIP() << "the Vulkan device " << vk->deviceName() << " does not share memory with the CUDA GPU";
  Scene scene = loadScene("cornell");
  Renderer renderer(scene, BackendKind::Cuda);
  renderer.rig().width = 320, renderer.rig().height = 356;
  renderer.options().photonsX = renderer.options().photonsY = 128;
  FrameResult frame = renderer.renderFrame(renderer.rig().head);  // host copies, for the reference
  const int w = renderer.rig().width, h = renderer.rig().height;
  for (int variant = 0; variant < 4; ++variant) {
    const DisplayEncoding encoding = variant % 2 ? DisplayEncoding::Rgba16Float : DisplayEncoding::Rgba8Srgb;
    SCOPED_TRACE(std::string(variant % 2 ? "half" : "sRGB") + (variant / 2 ? ", shared image" : ", shared buffer"));
    VkFormat format = encoding == DisplayEncoding::Rgba8Srgb ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_R16G16B16A16_SFLOAT;
    EyeTransferOptions o;
    o.width = w, o.height = h;
    o.encoding = encoding;
    o.depth = true;
    o.nearZ = 0.1f;
    o.path = HandOverPath::CudaShared;
    o.colourViaImage = variant / 2 == 1;
    EyeTransfer transfer(*vk, o);
    EXPECT_NE(transfer.describe().find(o.colourViaImage ? "image" : "buffer"), std::string::npos) << transfer.describe();
    VulkanImage colour[2], depth[2];
    EyeSource source[2];
    EyeTarget target[2];
    for (int e = 0; e < 2; ++e) {
      colour[e] = makeImage(*vk, w, h, format, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
      depth[e] = makeImage(*vk, w, h, VK_FORMAT_D32_SFLOAT, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
      vk->runOnce([&](VkCommandBuffer cmd) {
        transitionImage(cmd, colour[e].image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
        transitionImage(cmd, depth[e].image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
      });
      source[e].deviceImage = renderer.deviceImage(Eye(e));
      source[e].deviceInverseDepth = renderer.deviceInverseDepth(Eye(e));
      source[e].deviceStream = renderer.deviceStream();
      ASSERT_NE(source[e].deviceImage, nullptr);
      target[e] = {colour[e].image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, depth[e].image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
    }
    for (int i = 0; i < 3; ++i) transfer.handOver(source, target);
    HandOverTiming t = transfer.lastTiming();
    EXPECT_GT(t.encodeMs, 0.0);
    const int bpp = displayBytesPerPixel(encoding);
    for (int e = 0; e < 2; ++e) {
      std::vector<unsigned char> got = readImage(*vk, colour[e].image, VK_IMAGE_ASPECT_COLOR_BIT, w, h, bpp, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
      const Image& image = frame.eyes[e].image;
      size_t off = 0;
      for (size_t i = 0; i < image.pixels.size(); ++i) {
        unsigned char want[8];
        encodeDisplayPixel(image.pixels[i], 1.0f, encoding, want);
        if (encoding == DisplayEncoding::Rgba16Float) {
          off += std::memcmp(want, &got[i * bpp], 8) != 0;  // halves from the same floats: exact
        } else {
          for (int c = 0; c < 4; ++c) off += std::abs(int(want[c]) - int(got[i * bpp + c])) > 1;
        }
      }
      EXPECT_EQ(off, 0u) << "eye " << e;
      std::vector<unsigned char> d = readImage(*vk, depth[e].image, VK_IMAGE_ASPECT_DEPTH_BIT, w, h, 4, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
      size_t depthOff = 0;
      for (size_t i = 0; i < frame.eyes[e].inverseDepth.size(); ++i) {
        float v;
        std::memcpy(&v, &d[i * 4], 4);
        depthOff += v != reversedDepth(frame.eyes[e].inverseDepth[i], 0.1f);
      }
      EXPECT_EQ(depthOff, 0u) << "eye " << e;
    }
  }
}

}  // namespace
}  // namespace pvr
