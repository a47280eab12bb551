#include "pvr/raster/gbuffer_raster.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "pvr/scene/scene.h"
#include "pvr/util/error.h"

namespace pvr {
namespace {

const uint32_t kVertexShader[] = {
#include "pvr/raster/visibility.vert.inc"
};
const uint32_t kFragmentShader[] = {
#include "pvr/raster/visibility.frag.inc"
};

constexpr VkFormat kTriangleFormat = VK_FORMAT_R32_UINT;
constexpr VkFormat kBarycentricFormat = VK_FORMAT_R32G32_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr uint32_t kBothViews = 0b11;

void requireFormat(const VulkanContext& vk, VkFormat format, VkFormatFeatureFlags features, const char* what) {
  VkFormatProperties p;
  vkGetPhysicalDeviceFormatProperties(vk.physicalDevice(), format, &p);
  if ((p.optimalTilingFeatures & features) != features)
    throw Error("--primary raster: the Vulkan device '" + vk.deviceName() + "' cannot render " + what);
}

VkShaderModule shaderModule(VkDevice device, const uint32_t* code, size_t bytes) {
  VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  ci.codeSize = bytes;
  ci.pCode = code;
  VkShaderModule m = VK_NULL_HANDLE;
  vkCheck(vkCreateShaderModule(device, &ci, nullptr, &m), "vkCreateShaderModule");
  return m;
}

// Both layers (a multiview pass), or one (a pass per view).
VkImageView layerView(VkDevice device, VkImage image, VkFormat format, VkImageAspectFlags aspect, int layer) {
  VkImageViewCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  ci.image = image;
  ci.viewType = layer < 0 ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D;
  ci.format = format;
  ci.subresourceRange = {aspect, 0, 1, layer < 0 ? 0u : uint32_t(layer), layer < 0 ? 2u : 1u};
  VkImageView v = VK_NULL_HANDLE;
  vkCheck(vkCreateImageView(device, &ci, nullptr, &v), "vkCreateImageView");
  return v;
}

// Device-local buffer filled from host data through a staging copy.
VulkanBuffer uploadBuffer(VulkanContext& vk, const void* data, size_t bytes, VkBufferUsageFlags usage) {
  VulkanBuffer staging = makeHostBuffer(vk, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  std::memcpy(staging.mapped, data, bytes);
  VulkanBuffer target = makeDeviceBuffer(vk, bytes, usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  vk.runOnce([&](VkCommandBuffer cmd) {
    VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(cmd, staging.buffer, target.buffer, 1, &region);
  });
  return target;
}

VkSemaphore exportableSemaphore(VkDevice device) {
  VkExportSemaphoreCreateInfo exportInfo{VK_STRUCTURE_TYPE_EXPORT_SEMAPHORE_CREATE_INFO};
  exportInfo.handleTypes = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
  VkSemaphoreCreateInfo ci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  ci.pNext = &exportInfo;
  VkSemaphore s = VK_NULL_HANDLE;
  vkCheck(vkCreateSemaphore(device, &ci, nullptr, &s), "vkCreateSemaphore (shared with CUDA)");
  return s;
}

}  // namespace

void rasterWorldToClip(const EyeCamera& camera, float nearDepth, float out[16]) {
  // View space: v = A p + b (EyeCamera's pose), in double so that the matrix rounds once.
  const Vec3 origin = camera.pose.toLocalPoint(Vec3{0, 0, 0});
  double view[3][4];
  for (int c = 0; c < 3; ++c) {
    Vec3 axis{c == 0 ? 1.0f : 0.0f, c == 1 ? 1.0f : 0.0f, c == 2 ? 1.0f : 0.0f};
    Vec3 column = camera.pose.orientation.conjugate().rotate(axis);
    view[0][c] = column.x, view[1][c] = column.y, view[2][c] = column.z;
  }
  view[0][3] = origin.x, view[1][3] = origin.y, view[2][3] = origin.z;
  const double tl = std::tan(double(camera.fov.angleLeft)), tr = std::tan(double(camera.fov.angleRight));
  const double tu = std::tan(double(camera.fov.angleUp)), td = std::tan(double(camera.fov.angleDown));
  // clip = P v: x' = a vx + bx vz, y' = c vy + by vz (framebuffer rows grow downwards), z' = near, w' = -vz.
  const double a = 2.0 / (tr - tl), bx = (tr + tl) / (tr - tl);
  const double c = -2.0 / (tu - td), by = -(tu + td) / (tu - td);
  double m[4][4] = {};
  for (int col = 0; col < 4; ++col) {
    m[0][col] = a * view[0][col] + bx * view[2][col];
    m[1][col] = c * view[1][col] + by * view[2][col];
    m[3][col] = -view[2][col];
  }
  m[2][3] = nearDepth;
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) out[col * 4 + row] = float(m[row][col]);
}

size_t gbufferBytes(int width, int height) {
  return size_t(width) * size_t(height) * 2 * (sizeof(uint32_t) + sizeof(Vec2));
}

PrimaryHitsView gbufferEyeView(const void* base, int width, int height, Eye eye) {
  const size_t pixels = size_t(width) * size_t(height);
  const auto* bytes = static_cast<const unsigned char*>(base);
  PrimaryHitsView v;
  v.prim = reinterpret_cast<const uint32_t*>(bytes) + pixels * size_t(eye);
  v.barycentrics = reinterpret_cast<const Vec2*>(bytes + 2 * pixels * sizeof(uint32_t)) + pixels * size_t(eye);
  v.width = width;
  return v;
}

struct GBufferRaster::Impl {
  VkDevice device = VK_NULL_HANDLE;
  VkCommandPool commandPool = VK_NULL_HANDLE;
  VulkanBuffer positions, indices, hits;
  uint32_t triangles = 0;
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout pipelineLayout = VK_NULL_HANDLE;
  VkRenderPass renderPass = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  VulkanImage triangleImage, barycentricImage, depthImage;
  bool multiview = true;      ///< one pass for both eyes; else a pass per eye (each its own layer)
  VkImageView views[6] = {};  ///< triangle, barycentrics, depth: both layers, or layer 0 then layer 1
  VkFramebuffer framebuffers[2] = {};
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  bool submitted = false;
  VkQueryPool timestamps = VK_NULL_HANDLE;
  double timestampPeriodNs = 1.0;
  uint64_t timestampMask = ~0ull;
  VkSemaphore rasterDone = VK_NULL_HANDLE, readersDone = VK_NULL_HANDLE;
  PFN_vkGetMemoryFdKHR getMemoryFd = nullptr;
  PFN_vkGetSemaphoreFdKHR getSemaphoreFd = nullptr;

  ~Impl() {
    if (!device) return;
    if (submitted) vkWaitForFences(device, 1, &fence, VK_TRUE, 10'000'000'000ull);
    destroyTargets();
    if (rasterDone) vkDestroySemaphore(device, rasterDone, nullptr);
    if (readersDone) vkDestroySemaphore(device, readersDone, nullptr);
    if (timestamps) vkDestroyQueryPool(device, timestamps, nullptr);
    if (fence) vkDestroyFence(device, fence, nullptr);
    if (cmd) vkFreeCommandBuffers(device, commandPool, 1, &cmd);
    if (pipeline) vkDestroyPipeline(device, pipeline, nullptr);
    if (renderPass) vkDestroyRenderPass(device, renderPass, nullptr);
    if (pool) vkDestroyDescriptorPool(device, pool, nullptr);
    if (pipelineLayout) vkDestroyPipelineLayout(device, pipelineLayout, nullptr);
    if (setLayout) vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
  }

  void destroyTargets() {
    for (VkFramebuffer& f : framebuffers)
      if (f) vkDestroyFramebuffer(device, f, nullptr), f = VK_NULL_HANDLE;
    for (VkImageView& v : views)
      if (v) vkDestroyImageView(device, v, nullptr), v = VK_NULL_HANDLE;
    triangleImage = VulkanImage(), barycentricImage = VulkanImage(), depthImage = VulkanImage();
    hits = VulkanBuffer();
  }
};

GBufferRaster::GBufferRaster(VulkanContext& vk, const Scene& scene, bool shareWithCuda, GBufferViews views)
    : vk_(vk), impl_(std::make_unique<Impl>()), shared_(shareWithCuda) {
  Impl& s = *impl_;
  s.multiview = views == GBufferViews::Multiview || (views == GBufferViews::Auto && !vk.isCpuDevice());
  s.device = vk.device();
  s.commandPool = vk.commandPool();
  if (!vk.hasMultiview())
    throw Error("--primary raster: the Vulkan device '" + vk.deviceName() + "' has no multiview (both eyes in one pass)");
  if (shareWithCuda && !vk.canShareWithCuda())
    throw Error("--primary raster: the Vulkan device '" + vk.deviceName() + "' cannot share memory with CUDA");
  if (scene.triangleCount() == 0) throw Error("--primary raster: the scene has no triangles");
  if (uint64_t(scene.triangleCount()) * 3 > uint64_t(UINT32_MAX))
    throw Error("--primary raster: more triangles than one draw can hold");
  requireFormat(vk, kTriangleFormat, VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT, "R32_UINT triangle ids");
  requireFormat(vk, kBarycentricFormat, VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT, "R32G32_SFLOAT barycentrics");
  requireFormat(vk, kDepthFormat, VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT, "D32_SFLOAT depth");
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(vk.physicalDevice(), &props);
  const size_t positionBytes = scene.vertices().size() * sizeof(Vec3), indexBytes = scene.indices().size() * sizeof(uint32_t);
  if (std::max(positionBytes, indexBytes) > props.limits.maxStorageBufferRange)
    throw Error("--primary raster: the scene's " + std::to_string(scene.triangleCount()) +
                " triangles exceed the Vulkan device's storage buffer range (" +
                std::to_string(props.limits.maxStorageBufferRange >> 20) + " MiB)");
  s.timestampPeriodNs = props.limits.timestampPeriod;
  const Bounds3 bounds = scene.bounds();
  nearDepth_ = std::max(1e-6f * length(bounds.upper - bounds.lower), 1e-7f);
  static_assert(sizeof(Vec3) == 12, "positions are read as packed xyz floats");
  s.triangles = scene.triangleCount();
  s.positions = uploadBuffer(vk, scene.vertices().data(), positionBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  s.indices = uploadBuffer(vk, scene.indices().data(), indexBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);

  {  // whatever throws from here on, ~Impl releases what was made
    VkDescriptorSetLayoutBinding bindings[2] = {};
    for (uint32_t i = 0; i < 2; ++i) {
      bindings[i].binding = i;
      bindings[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      bindings[i].descriptorCount = 1;
      bindings[i].stageFlags = VK_SHADER_STAGE_VERTEX_BIT;
    }
    VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    lci.bindingCount = 2;
    lci.pBindings = bindings;
    vkCheck(vkCreateDescriptorSetLayout(s.device, &lci, nullptr, &s.setLayout), "vkCreateDescriptorSetLayout");
    VkPushConstantRange push{VK_SHADER_STAGE_VERTEX_BIT, 0, 2 * 16 * sizeof(float)};
    VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    plci.setLayoutCount = 1;
    plci.pSetLayouts = &s.setLayout;
    plci.pushConstantRangeCount = 1;
    plci.pPushConstantRanges = &push;
    vkCheck(vkCreatePipelineLayout(s.device, &plci, nullptr, &s.pipelineLayout), "vkCreatePipelineLayout");

    VkDescriptorPoolSize poolSize{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2};
    VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dpci.maxSets = 1;
    dpci.poolSizeCount = 1;
    dpci.pPoolSizes = &poolSize;
    vkCheck(vkCreateDescriptorPool(s.device, &dpci, nullptr, &s.pool), "vkCreateDescriptorPool");
    VkDescriptorSetAllocateInfo dsai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    dsai.descriptorPool = s.pool;
    dsai.descriptorSetCount = 1;
    dsai.pSetLayouts = &s.setLayout;
    vkCheck(vkAllocateDescriptorSets(s.device, &dsai, &s.set), "vkAllocateDescriptorSets");
    VkDescriptorBufferInfo infos[2] = {{s.positions.buffer, 0, VK_WHOLE_SIZE}, {s.indices.buffer, 0, VK_WHOLE_SIZE}};
    VkWriteDescriptorSet writes[2] = {};
    for (uint32_t i = 0; i < 2; ++i) {
      writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
      writes[i].dstSet = s.set;
      writes[i].dstBinding = i;
      writes[i].descriptorCount = 1;
      writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      writes[i].pBufferInfo = &infos[i];
    }
    vkUpdateDescriptorSets(s.device, 2, writes, 0, nullptr);

    // Render pass: two colour targets and depth, both views at once; the colours end ready to copy.
    VkAttachmentDescription attachments[3] = {};
    const VkFormat formats[3] = {kTriangleFormat, kBarycentricFormat, kDepthFormat};
    for (int i = 0; i < 3; ++i) {
      attachments[i].format = formats[i];
      attachments[i].samples = VK_SAMPLE_COUNT_1_BIT;
      attachments[i].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
      attachments[i].storeOp = i < 2 ? VK_ATTACHMENT_STORE_OP_STORE : VK_ATTACHMENT_STORE_OP_DONT_CARE;
      attachments[i].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
      attachments[i].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
      attachments[i].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
      attachments[i].finalLayout = i < 2 ? VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL : VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    }
    VkAttachmentReference colourRefs[2] = {{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL}, {1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL}};
    VkAttachmentReference depthRef{2, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    VkSubpassDescription subpass{};
    subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    subpass.colorAttachmentCount = 2;
    subpass.pColorAttachments = colourRefs;
    subpass.pDepthStencilAttachment = &depthRef;
    VkSubpassDependency deps[2] = {};
    deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;  // the last frame's copies read the targets first
    deps[0].dstSubpass = 0;
    deps[0].srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
    deps[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT;
    deps[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    deps[1].srcSubpass = 0;  // then this frame's copies read them
    deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
    deps[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
    deps[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    deps[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    VkRenderPassMultiviewCreateInfo multiview{VK_STRUCTURE_TYPE_RENDER_PASS_MULTIVIEW_CREATE_INFO};
    multiview.subpassCount = 1;
    multiview.pViewMasks = &kBothViews;
    multiview.correlationMaskCount = 1;
    multiview.pCorrelationMasks = &kBothViews;
    VkRenderPassCreateInfo rpci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    rpci.pNext = s.multiview ? &multiview : nullptr;
    rpci.attachmentCount = 3;
    rpci.pAttachments = attachments;
    rpci.subpassCount = 1;
    rpci.pSubpasses = &subpass;
    rpci.dependencyCount = 2;
    rpci.pDependencies = deps;
    vkCheck(vkCreateRenderPass(s.device, &rpci, nullptr, &s.renderPass), "vkCreateRenderPass (G-buffer)");

    VkShaderModule vert = shaderModule(s.device, kVertexShader, sizeof(kVertexShader));
    VkShaderModule frag = shaderModule(s.device, kFragmentShader, sizeof(kFragmentShader));
    VkPipelineShaderStageCreateInfo stages[2] = {};
    stages[0].sType = stages[1].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT, stages[0].module = vert, stages[0].pName = "main";
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT, stages[1].module = frag, stages[1].pName = "main";
    VkPipelineVertexInputStateCreateInfo vertexInput{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    VkPipelineInputAssemblyStateCreateInfo assembly{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = VK_CULL_MODE_NONE;  // rays see both sides
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    raster.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo multisample{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    VkPipelineDepthStencilStateCreateInfo depth{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    depth.depthTestEnable = VK_TRUE;
    depth.depthWriteEnable = VK_TRUE;
    depth.depthCompareOp = VK_COMPARE_OP_GREATER;  // reversed Z
    VkPipelineColorBlendAttachmentState blend[2] = {};  // identical (no independentBlend needed); absent channels are not written
    for (VkPipelineColorBlendAttachmentState& b : blend)
      b.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    VkPipelineColorBlendStateCreateInfo colourBlend{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    colourBlend.attachmentCount = 2;
    colourBlend.pAttachments = blend;
    const VkDynamicState dynamicStates[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic.dynamicStateCount = 2;
    dynamic.pDynamicStates = dynamicStates;
    VkGraphicsPipelineCreateInfo gpci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    gpci.stageCount = 2;
    gpci.pStages = stages;
    gpci.pVertexInputState = &vertexInput;
    gpci.pInputAssemblyState = &assembly;
    gpci.pViewportState = &viewport;
    gpci.pRasterizationState = &raster;
    gpci.pMultisampleState = &multisample;
    gpci.pDepthStencilState = &depth;
    gpci.pColorBlendState = &colourBlend;
    gpci.pDynamicState = &dynamic;
    gpci.layout = s.pipelineLayout;
    gpci.renderPass = s.renderPass;
    VkResult r = vkCreateGraphicsPipelines(s.device, VK_NULL_HANDLE, 1, &gpci, nullptr, &s.pipeline);
    vkDestroyShaderModule(s.device, vert, nullptr);
    vkDestroyShaderModule(s.device, frag, nullptr);
    vkCheck(r, "vkCreateGraphicsPipelines (visibility pass)");

    VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cai.commandPool = vk.commandPool();
    cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cai.commandBufferCount = 1;
    vkCheck(vkAllocateCommandBuffers(s.device, &cai, &s.cmd), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    vkCheck(vkCreateFence(s.device, &fci, nullptr, &s.fence), "vkCreateFence");
    VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qci.queryCount = 3;
    vkCheck(vkCreateQueryPool(s.device, &qci, nullptr, &s.timestamps), "vkCreateQueryPool");
    uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(vk.physicalDevice(), &families, nullptr);
    std::vector<VkQueueFamilyProperties> family(families);
    vkGetPhysicalDeviceQueueFamilyProperties(vk.physicalDevice(), &families, family.data());
    const uint32_t bits = family[vk.queueFamily()].timestampValidBits;
    s.timestampMask = bits >= 64 ? ~0ull : bits == 0 ? 0ull : (1ull << bits) - 1;
    if (shared_) {
      s.getMemoryFd = reinterpret_cast<PFN_vkGetMemoryFdKHR>(vkGetDeviceProcAddr(s.device, "vkGetMemoryFdKHR"));
      s.getSemaphoreFd = reinterpret_cast<PFN_vkGetSemaphoreFdKHR>(vkGetDeviceProcAddr(s.device, "vkGetSemaphoreFdKHR"));
      if (!s.getMemoryFd || !s.getSemaphoreFd) throw Error("--primary raster: the Vulkan driver exports no file descriptors");
      s.rasterDone = exportableSemaphore(s.device);
      s.readersDone = exportableSemaphore(s.device);
    }
  }
}

GBufferRaster::~GBufferRaster() = default;

void GBufferRaster::resize(int width, int height) {
  Impl& s = *impl_;
  s.destroyTargets();
  width_ = height_ = 0;  // until everything below exists: a failed resize is retried by the next render
  const VkImageUsageFlags colour = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  s.triangleImage = makeImage(vk_, width, height, kTriangleFormat, colour, 2);
  s.barycentricImage = makeImage(vk_, width, height, kBarycentricFormat, colour, 2);
  s.depthImage = makeImage(vk_, width, height, kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, 2);
  for (int pass = 0; pass < (s.multiview ? 1 : 2); ++pass) {
    const int layer = s.multiview ? -1 : pass;
    VkImageView* v = s.views + 3 * pass;
    v[0] = layerView(s.device, s.triangleImage.image, kTriangleFormat, VK_IMAGE_ASPECT_COLOR_BIT, layer);
    v[1] = layerView(s.device, s.barycentricImage.image, kBarycentricFormat, VK_IMAGE_ASPECT_COLOR_BIT, layer);
    v[2] = layerView(s.device, s.depthImage.image, kDepthFormat, VK_IMAGE_ASPECT_DEPTH_BIT, layer);
    VkFramebufferCreateInfo fci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fci.renderPass = s.renderPass;
    fci.attachmentCount = 3;
    fci.pAttachments = v;
    fci.width = uint32_t(width);
    fci.height = uint32_t(height);
    fci.layers = 1;  // multiview: the views are the layers
    vkCheck(vkCreateFramebuffer(s.device, &fci, nullptr, &s.framebuffers[pass]), "vkCreateFramebuffer");
  }
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  const size_t bytes = gbufferBytes(width, height);
  s.hits = shared_ ? makeExportableBuffer(vk_, bytes, usage) : makeHostBuffer(vk_, bytes, usage);
  width_ = width, height_ = height;
  ++generation_;
}

size_t GBufferRaster::bufferBytes() const {
  return gbufferBytes(width_, height_);
}

size_t GBufferRaster::bufferAllocationBytes() const { return size_t(impl_->hits.allocationSize); }

void GBufferRaster::waitDone() {
  Impl& s = *impl_;
  if (!s.submitted) return;
  VkResult r = vkWaitForFences(s.device, 1, &s.fence, VK_TRUE, 10'000'000'000ull);
  if (r == VK_TIMEOUT) throw Error("Vulkan: the G-buffer pre-pass did not finish within 10 s");
  vkCheck(r, "vkWaitForFences (G-buffer pre-pass)");
}

void GBufferRaster::render(const EyeCamera eyes[2], bool waitForReaders) {
  Impl& s = *impl_;
  if (eyes[0].width != eyes[1].width || eyes[0].height != eyes[1].height)
    throw Error("--primary raster: both eyes must have the same size");
  waitDone();  // the command buffer and the targets are free again
  if (s.submitted) vkCheck(vkResetFences(s.device, 1, &s.fence), "vkResetFences");
  s.submitted = false;
  if (eyes[0].width != width_ || eyes[0].height != height_) resize(eyes[0].width, eyes[0].height);
  float worldToClip[32];
  rasterWorldToClip(eyes[0], nearDepth_, worldToClip);
  rasterWorldToClip(eyes[1], nearDepth_, worldToClip + 16);

  VkCommandBuffer cmd = s.cmd;
  vkCheck(vkResetCommandBuffer(cmd, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkCheck(vkBeginCommandBuffer(cmd, &bi), "vkBeginCommandBuffer");
  vkCmdResetQueryPool(cmd, s.timestamps, 0, 3);
  vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, s.timestamps, 0);
  VkClearValue clears[3] = {};
  clears[0].color.uint32[0] = ~0u;  // no triangle: the sky
  clears[2].depthStencil = {0.0f, 0};  // reversed Z: 0 is infinitely far
  // Multiview: one pass, gl_ViewIndex picks the eye's transform. A pass per eye: gl_ViewIndex is 0,
  // so each pass gets its eye's transform in the first slot.
  for (int pass = 0; pass < (s.multiview ? 1 : 2); ++pass) {
    VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    rbi.renderPass = s.renderPass;
    rbi.framebuffer = s.framebuffers[pass];
    rbi.renderArea = {{0, 0}, {uint32_t(width_), uint32_t(height_)}};
    rbi.clearValueCount = 3;
    rbi.pClearValues = clears;
    vkCmdBeginRenderPass(cmd, &rbi, VK_SUBPASS_CONTENTS_INLINE);
    VkViewport viewport{0.0f, 0.0f, float(width_), float(height_), 0.0f, 1.0f};
    VkRect2D scissor{{0, 0}, {uint32_t(width_), uint32_t(height_)}};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, s.pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, s.pipelineLayout, 0, 1, &s.set, 0, nullptr);
    if (s.multiview)
      vkCmdPushConstants(cmd, s.pipelineLayout, VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof(worldToClip), worldToClip);
    else
      vkCmdPushConstants(cmd, s.pipelineLayout, VK_SHADER_STAGE_VERTEX_BIT, 0, 16 * sizeof(float), worldToClip + 16 * pass);
    vkCmdDraw(cmd, 3 * s.triangles, 1, 0, 0);
    vkCmdEndRenderPass(cmd);
  }
  vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_ALL_GRAPHICS_BIT, s.timestamps, 1);
  // Both views of each target into the buffer, planes as primary_hits.h reads them.
  const VkDeviceSize pixels = VkDeviceSize(width_) * VkDeviceSize(height_);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 2};
  region.imageExtent = {uint32_t(width_), uint32_t(height_), 1};
  vkCmdCopyImageToBuffer(cmd, s.triangleImage.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, s.hits.buffer, 1, &region);
  region.bufferOffset = 2 * pixels * sizeof(uint32_t);
  vkCmdCopyImageToBuffer(cmd, s.barycentricImage.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, s.hits.buffer, 1, &region);
  VkMemoryBarrier written{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  written.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  written.dstAccessMask = shared_ ? VK_ACCESS_MEMORY_READ_BIT : VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT,
                       shared_ ? VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT : VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &written, 0,
                       nullptr, 0, nullptr);
  vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, s.timestamps, 2);
  vkCheck(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");

  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  const VkPipelineStageFlags waitStage = VK_PIPELINE_STAGE_TRANSFER_BIT;  // only the copies touch what CUDA reads
  if (shared_ && waitForReaders) {
    si.waitSemaphoreCount = 1;
    si.pWaitSemaphores = &s.readersDone;
    si.pWaitDstStageMask = &waitStage;
  }
  if (shared_) {
    si.signalSemaphoreCount = 1;
    si.pSignalSemaphores = &s.rasterDone;
  }
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  vkCheck(queueSubmit(vk_.queue(), 1, &si, s.fence), "vkQueueSubmit (G-buffer pre-pass)");
  s.submitted = true;
}

PrimaryHitsView GBufferRaster::hostView(Eye eye) const {
  if (shared_ || !impl_->hits.mapped) return PrimaryHitsView();
  return gbufferEyeView(impl_->hits.mapped, width_, height_, eye);
}

double GBufferRaster::lastGpuMs(double* drawMs) {
  Impl& s = *impl_;
  if (!s.submitted || s.timestampMask == 0) return 0.0;
  waitDone();
  uint64_t t[3] = {0, 0, 0};
  VkResult r = vkGetQueryPoolResults(s.device, s.timestamps, 0, 3, sizeof(t), t, sizeof(uint64_t),
                                     VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
  if (r != VK_SUCCESS) return 0.0;
  const double toMs = s.timestampPeriodNs * 1e-6;
  if (drawMs) *drawMs = double((t[1] - t[0]) & s.timestampMask) * toMs;
  return double((t[2] - t[0]) & s.timestampMask) * toMs;
}

int GBufferRaster::exportBufferFd() const {
  VkMemoryGetFdInfoKHR info{VK_STRUCTURE_TYPE_MEMORY_GET_FD_INFO_KHR};
  info.memory = impl_->hits.memory;
  info.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  int fd = -1;
  vkCheck(impl_->getMemoryFd(impl_->device, &info, &fd), "vkGetMemoryFdKHR (G-buffer)");
  return fd;
}

namespace {
int semaphoreFd(PFN_vkGetSemaphoreFdKHR get, VkDevice device, VkSemaphore semaphore) {
  VkSemaphoreGetFdInfoKHR info{VK_STRUCTURE_TYPE_SEMAPHORE_GET_FD_INFO_KHR};
  info.semaphore = semaphore;
  info.handleType = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
  int fd = -1;
  vkCheck(get(device, &info, &fd), "vkGetSemaphoreFdKHR (G-buffer)");
  return fd;
}
}  // namespace

std::string GBufferRaster::describe() const {
  return impl_->multiview ? "both eyes in one multiview pass on " + vk_.deviceName()
                          : "a pass per eye on " + vk_.deviceName() + " (a CPU device: its multiview misplaces clipped triangles)";
}

bool GBufferRaster::multiview() const { return impl_->multiview; }

int GBufferRaster::exportRasterDoneFd() const { return semaphoreFd(impl_->getSemaphoreFd, impl_->device, impl_->rasterDone); }
int GBufferRaster::exportReadersDoneFd() const { return semaphoreFd(impl_->getSemaphoreFd, impl_->device, impl_->readersDone); }

}  // namespace pvr
