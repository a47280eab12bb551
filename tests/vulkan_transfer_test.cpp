// The Vulkan hand-over on whatever Vulkan device this machine has (lavapipe in CI): an image
// rendered by the CPU backend arrives in a Vulkan image bit for bit in the display's encoding,
// and its depth as reversed-Z floats. Skips without a Vulkan driver unless PVR_REQUIRE_VULKAN=1
// (the test script sets it, so CI cannot pass by skipping).
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>

#include "pvr/image/image_io.h"
#include "pvr/render/renderer.h"
#include "pvr/scene/scene.h"
#include "pvr/util/error.h"
#include "vulkan_test_context.h"
#include "pvr/vk/eye_transfer.h"

namespace pvr {
namespace {

struct Rendered {
  FrameResult frame;
  int width = 40, height = 36;
};

const Rendered& cornell() {
  static Rendered r = [] {
    Rendered out;
    static Scene scene = loadScene("cornell");
    Renderer renderer(scene, BackendKind::Cpu);
    renderer.rig().width = out.width, renderer.rig().height = out.height;
    renderer.options().photonsX = renderer.options().photonsY = 64;
    out.frame = renderer.renderFrame(renderer.rig().head);
    return out;
  }();
  return r;
}

std::vector<unsigned char> expectedBytes(const Image& image, DisplayEncoding encoding, float exposure) {
  const int bpp = displayBytesPerPixel(encoding);
  std::vector<unsigned char> bytes(image.pixels.size() * bpp);
  for (size_t i = 0; i < image.pixels.size(); ++i) encodeDisplayPixel(image.pixels[i], exposure, encoding, &bytes[i * bpp]);
  return bytes;
}

void roundTrip(VkFormat format, DisplayEncoding encoding) {
  auto vk = test::vulkanContextOrSkip();
  if (!vk) GTEST_SKIP() << "no Vulkan device on this machine";
  const Rendered& r = cornell();
  EyeTransferOptions o;
  o.width = r.width, o.height = r.height;
  o.encoding = encoding;
  o.depth = true;
  o.nearZ = 0.1f;
  o.exposure = 1.5f;
  EyeTransfer transfer(*vk, o);
  VulkanImage colour[2], depth[2];
  EyeSource source[2];
  EyeTarget target[2];
  for (int e = 0; e < 2; ++e) {
    colour[e] = makeImage(*vk, r.width, r.height, format, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    depth[e] = makeImage(*vk, r.width, r.height, VK_FORMAT_D32_SFLOAT, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    vk->runOnce([&](VkCommandBuffer cmd) {
      transitionImage(cmd, colour[e].image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
      transitionImage(cmd, depth[e].image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    });
    source[e].image = &r.frame.eyes[e].image;
    source[e].inverseDepth = &r.frame.eyes[e].inverseDepth;
    target[e] = {colour[e].image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, depth[e].image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
  }
  for (int frame = 0; frame < 3; ++frame) transfer.handOver(source, target);  // both slots used, one reused
  transfer.waitIdle();
  for (int e = 0; e < 2; ++e) {
    std::vector<unsigned char> got = readImage(*vk, colour[e].image, VK_IMAGE_ASPECT_COLOR_BIT, r.width, r.height,
                                               displayBytesPerPixel(encoding), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    EXPECT_EQ(got, expectedBytes(r.frame.eyes[e].image, encoding, 1.5f)) << "eye " << e;
    std::vector<unsigned char> d = readImage(*vk, depth[e].image, VK_IMAGE_ASPECT_DEPTH_BIT, r.width, r.height, 4,
                                             VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    size_t background = 0;
    for (size_t i = 0; i < r.frame.eyes[e].inverseDepth.size(); ++i) {
      float value;
      std::memcpy(&value, &d[i * 4], 4);
      ASSERT_EQ(value, reversedDepth(r.frame.eyes[e].inverseDepth[i], 0.1f)) << "pixel " << i;
      background += r.frame.eyes[e].inverseDepth[i] == 0.0f ? 1 : 0;
    }
    EXPECT_LT(background, r.frame.eyes[e].inverseDepth.size());  // the box is seen
  }
}

TEST(VulkanTransfer, Rgba8SrgbArrivesBitForBit) { roundTrip(VK_FORMAT_R8G8B8A8_SRGB, DisplayEncoding::Rgba8Srgb); }
TEST(VulkanTransfer, Bgra8SrgbArrivesBitForBit) { roundTrip(VK_FORMAT_B8G8R8A8_SRGB, DisplayEncoding::Bgra8Srgb); }
TEST(VulkanTransfer, HalfFloatArrivesBitForBit) { roundTrip(VK_FORMAT_R16G16B16A16_SFLOAT, DisplayEncoding::Rgba16Float); }

// The sRGB bytes are the PNG's: what a headset shows is what `render` writes.
TEST(DisplayEncoding, SrgbBytesAreThePngBytes) {
  const Rendered& r = cornell();
  const Image& image = r.frame.eyes[0].image;
  std::vector<unsigned char> bytes = expectedBytes(image, DisplayEncoding::Rgba8Srgb, 1.0f);
  for (size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) ASSERT_EQ(bytes[4 * i + c], (unsigned char)std::lround(255.0f * linearToSrgb(image.pixels[i][c])));
}

TEST(DisplayEncoding, HalfFloatsAreIeee) {
  EXPECT_EQ(floatToHalf(1.0f), 0x3c00u);
  EXPECT_EQ(floatToHalf(0.5f), 0x3800u);
  EXPECT_EQ(floatToHalf(65504.0f), 0x7bffu);
  EXPECT_EQ(floatToHalf(1e6f), 0x7c00u);          // overflow: infinity
  EXPECT_EQ(floatToHalf(5.9604645e-8f), 0x0001u);  // smallest subnormal
  EXPECT_EQ(floatToHalf(1.0f + 1.0f / 2048.0f), 0x3c00u);  // a tie rounds to even
  EXPECT_EQ(floatToHalf(1.0f + 3.0f / 2048.0f), 0x3c02u);
  EXPECT_EQ(floatToHalf(-2.0f), 0xc000u);
}

TEST(DisplayEncoding, NonFiniteShowsBlackAndDepthIsClamped) {
  unsigned char px[4];
  encodeDisplayPixel({NAN, INFINITY, -1.0f}, 1.0f, DisplayEncoding::Rgba8Srgb, px);
  EXPECT_EQ(px[0], 0);
  EXPECT_EQ(px[1], 0);
  EXPECT_EQ(px[2], 0);
  EXPECT_EQ(px[3], 255);
  EXPECT_EQ(reversedDepth(0.0f, 0.05f), 0.0f);      // nothing hit: infinitely far
  EXPECT_EQ(reversedDepth(100.0f, 0.05f), 1.0f);    // nearer than nearZ: clamped
  EXPECT_FLOAT_EQ(reversedDepth(1.0f, 0.05f), 0.05f);  // 1 m away
}

}  // namespace
}  // namespace pvr
