#include "pvr/viewer/viewer_presenter.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_vulkan.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>

#include "pvr/foveation/mask.h"
#include "pvr/image/image_io.h"
#include "pvr/util/error.h"
#include "pvr/vk/eye_transfer.h"
#include "pvr/vk/frame_source.h"
#include "pvr/vulkan/vulkan_context.h"
#ifdef PVR_HAVE_CUDA
#include "pvr/cuda/display_handover.h"
#endif

namespace pvr {

std::vector<ScriptedKey> parseKeyScript(const std::string& text) {
  static const std::map<std::string, int> names = {
      {"F12", GLFW_KEY_F12}, {"Escape", GLFW_KEY_ESCAPE}, {"W", GLFW_KEY_W}, {"A", GLFW_KEY_A}, {"S", GLFW_KEY_S},
      {"D", GLFW_KEY_D},     {"Q", GLFW_KEY_Q},           {"E", GLFW_KEY_E}, {"Tab", GLFW_KEY_TAB}, {"R", GLFW_KEY_R}};
  std::vector<ScriptedKey> keys;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find(',', start);
    std::string entry = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
    start = end == std::string::npos ? text.size() : end + 1;
    size_t colon = entry.find(':');
    unsigned long long frame = 0;
    char extra = 0;
    if (colon == std::string::npos || std::sscanf(entry.substr(0, colon).c_str(), "%llu%c", &frame, &extra) != 1)
      throw Error("--keys entries are FRAME:KEY (e.g. 3:F12,5:Escape), got '" + entry + "'");
    auto key = names.find(entry.substr(colon + 1));
    if (key == names.end()) throw Error("--keys: unknown key '" + entry.substr(colon + 1) + "' (F12, Escape, W, A, S, D, Q, E, Tab, R)");
    keys.push_back({frame, key->second});
  }
  return keys;
}

namespace {

constexpr int kPanelWidth = 420;
constexpr size_t kPlotFrames = 240;

const char* const kKernels[] = {"single", "hybrid", "shared", "sorted"};
const char* const kStereo[] = {"separate", "scatter", "gather"};

void checkVk(VkResult r) {
  if (r != VK_SUCCESS) throw Error(std::string("Vulkan (Dear ImGui): ") + vkResultName(r));
}

}  // namespace

struct ViewerPresenter::Impl {
  StereoRig rig;
  ViewerSettings settings, applied;
  ViewerOptions options;
  GLFWwindow* window = nullptr;
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  std::unique_ptr<VulkanContext> vk;
  std::unique_ptr<EyeTransfer> transfer;
  VulkanImage eyes[2];
  VkSwapchainKHR swapchain = VK_NULL_HANDLE;
  VkFormat swapFormat = VK_FORMAT_UNDEFINED;
  VkExtent2D extent{};
  bool swapReadable = false;
  std::vector<VkImage> swapImages;
  std::vector<VkImageView> views;
  std::vector<VkFramebuffer> framebuffers;
  VkRenderPass renderPass = VK_NULL_HANDLE;
  VkDescriptorPool imguiPool = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence frameFence = VK_NULL_HANDLE;
  VkSemaphore imageAvailable = VK_NULL_HANDLE;
  std::vector<VkSemaphore> renderFinished;  ///< one per swapchain image: a present may still wait on the last one
  bool imguiReady = false, stop = false, backendChange = false, screenshotRequested = false, windowShotPending = false;
  // The head: position, yaw and pitch from the rig's start, driven by the mouse and WASD.
  Vec3 position;
  Quat start;
  float yaw = 0, pitch = 0;
  double lastX = 0, lastY = 0;
  bool dragging = false;
  float gaze[2] = {0.5f, 0.5f};
  std::chrono::steady_clock::time_point lastFrame = std::chrono::steady_clock::now();
  uint64_t frame = 0;
  std::vector<float> plots[5];  // total, trace, build, left, right
  std::vector<std::string> written;
  int screenshotCount = 0;
  std::optional<FoveationMask> mask;
  std::optional<FrameRequest> lastRequest;

  void shutdown();

  void pressKey(int key) {
    if (key == GLFW_KEY_ESCAPE) stop = true;
    if (key == GLFW_KEY_F12) screenshotRequested = true;
    if (key == GLFW_KEY_TAB) settings.bothEyes = !settings.bothEyes;
    if (key == GLFW_KEY_R) yaw = pitch = 0, position = rig.head.position;
  }

  Quat orientation() const {
    return start * Quat::fromAxisAngle({0, 1, 0}, yaw) * Quat::fromAxisAngle({1, 0, 0}, pitch);
  }

  void createSwapchain() {
    VkSurfaceCapabilitiesKHR caps;
    checkVk(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(vk->physicalDevice(), surface, &caps));
    uint32_t n = 0;
    vkGetPhysicalDeviceSurfaceFormatsKHR(vk->physicalDevice(), surface, &n, nullptr);
    std::vector<VkSurfaceFormatKHR> formats(n);
    vkGetPhysicalDeviceSurfaceFormatsKHR(vk->physicalDevice(), surface, &n, formats.data());
    if (formats.empty()) throw Error("the window offers no Vulkan surface format");
    VkSurfaceFormatKHR chosen = formats[0];
    for (const VkSurfaceFormatKHR& f : formats)
      if (f.format == VK_FORMAT_B8G8R8A8_SRGB || f.format == VK_FORMAT_R8G8B8A8_SRGB) chosen = f;
    if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT))
      throw Error("the window's swapchain images cannot be copy targets (no TRANSFER_DST usage)");
    const bool eightBit = chosen.format == VK_FORMAT_B8G8R8A8_SRGB || chosen.format == VK_FORMAT_R8G8B8A8_SRGB ||
                          chosen.format == VK_FORMAT_B8G8R8A8_UNORM || chosen.format == VK_FORMAT_R8G8B8A8_UNORM;
    swapReadable = eightBit && (caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT);  // the window shot reads 8-bit RGBA
    swapFormat = chosen.format;
    int w = 0, h = 0;
    glfwGetFramebufferSize(window, &w, &h);
    extent = caps.currentExtent.width != UINT32_MAX ? caps.currentExtent : VkExtent2D{uint32_t(w), uint32_t(h)};
    if (extent.width == 0 || extent.height == 0) return;  // minimized: no swapchain until it is shown again
    VkSwapchainCreateInfoKHR sci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    sci.surface = surface;
    sci.minImageCount = std::max(caps.minImageCount, 2u);
    if (caps.maxImageCount) sci.minImageCount = std::min(sci.minImageCount, caps.maxImageCount);
    sci.imageFormat = chosen.format;
    sci.imageColorSpace = chosen.colorSpace;
    sci.imageExtent = extent;
    sci.imageArrayLayers = 1;
    sci.imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | (swapReadable ? VK_IMAGE_USAGE_TRANSFER_SRC_BIT : 0);
    sci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    sci.preTransform = caps.currentTransform;
    sci.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    sci.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // every driver has it; vsync-paced like a display
    sci.clipped = VK_TRUE;
    vkCheck(vkCreateSwapchainKHR(vk->device(), &sci, nullptr, &swapchain), "vkCreateSwapchainKHR");
    vkGetSwapchainImagesKHR(vk->device(), swapchain, &n, nullptr);
    swapImages.resize(n);
    vkGetSwapchainImagesKHR(vk->device(), swapchain, &n, swapImages.data());
    if (!renderPass) {
      VkAttachmentDescription colour{};
      colour.format = swapFormat;
      colour.samples = VK_SAMPLE_COUNT_1_BIT;
      colour.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;  // the eyes were blitted in before the panel
      colour.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
      colour.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
      colour.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
      colour.initialLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
      colour.finalLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
      VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
      VkSubpassDescription subpass{};
      subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
      subpass.colorAttachmentCount = 1;
      subpass.pColorAttachments = &ref;
      VkRenderPassCreateInfo rpci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
      rpci.attachmentCount = 1;
      rpci.pAttachments = &colour;
      rpci.subpassCount = 1;
      rpci.pSubpasses = &subpass;
      vkCheck(vkCreateRenderPass(vk->device(), &rpci, nullptr, &renderPass), "vkCreateRenderPass");
    }
    for (VkImage image : swapImages) {
      VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
      vci.image = image;
      vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
      vci.format = swapFormat;
      vci.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
      VkImageView view;
      vkCheck(vkCreateImageView(vk->device(), &vci, nullptr, &view), "vkCreateImageView");
      views.push_back(view);
      VkFramebufferCreateInfo fci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
      fci.renderPass = renderPass;
      fci.attachmentCount = 1;
      fci.pAttachments = &view;
      fci.width = extent.width;
      fci.height = extent.height;
      fci.layers = 1;
      VkFramebuffer fb;
      vkCheck(vkCreateFramebuffer(vk->device(), &fci, nullptr, &fb), "vkCreateFramebuffer");
      framebuffers.push_back(fb);
      VkSemaphoreCreateInfo semaphoreInfo{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
      VkSemaphore finished;
      vkCheck(vkCreateSemaphore(vk->device(), &semaphoreInfo, nullptr, &finished), "vkCreateSemaphore");
      renderFinished.push_back(finished);
    }
  }

  void destroySwapchain() {
    vkDeviceWaitIdle(vk->device());
    for (VkFramebuffer fb : framebuffers) vkDestroyFramebuffer(vk->device(), fb, nullptr);
    for (VkImageView v : views) vkDestroyImageView(vk->device(), v, nullptr);
    for (VkSemaphore s : renderFinished) vkDestroySemaphore(vk->device(), s, nullptr);
    framebuffers.clear(), views.clear(), swapImages.clear(), renderFinished.clear();
    if (swapchain) vkDestroySwapchainKHR(vk->device(), swapchain, nullptr);
    swapchain = VK_NULL_HANDLE;
  }

  void makeEyes(bool cudaShared) {
    transfer.reset();
    EyeTransferOptions to;
    to.width = rig.width, to.height = rig.height;
    to.encoding = DisplayEncoding::Rgba8Srgb;
    to.exposure = settings.exposure;
    to.path = cudaShared ? HandOverPath::CudaShared : HandOverPath::HostStaging;
    transfer = std::make_unique<EyeTransfer>(*vk, to);
    for (int e = 0; e < 2; ++e) {
      eyes[e] = makeImage(*vk, rig.width, rig.height, VK_FORMAT_R8G8B8A8_SRGB,
                          VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
      vk->runOnce([&](VkCommandBuffer c) {
        transitionImage(c, eyes[e].image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
      });
    }
  }

  void drawPanel(const PresentedFrame* frame) {
    ImGui_ImplVulkan_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    if (options.panel) {
      ImGui::SetNextWindowPos(ImVec2(float(extent.width) - kPanelWidth, 0));
      ImGui::SetNextWindowSize(ImVec2(kPanelWidth, float(extent.height)));
      ImGui::Begin("photonvr", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
      ImGui::PushItemWidth(230);
      if (frame && frame->result) {
        const StageTimings& t = frame->result->timings;
        ImGui::Text("%s, %s", frame->renderer.backendName().c_str(), frame->renderer.deviceName().c_str());
        ImGui::Text("%.2f ms: trace %.2f, map %.2f, eyes %.2f + %.2f", t.totalMs(), t.photonTraceMs, t.mapBuildMs, t.eyeMs[0], t.eyeMs[1]);
        if (t.primaryMs > 0) ImGui::Text("raster pre-pass %.2f ms", t.primaryMs);
      }
      static const char* plotNames[] = {"frame", "photon trace", "map build", "left eye", "right eye"};
      for (int p = 0; p < 5; ++p)
        if (!plots[p].empty())
          ImGui::PlotLines(plotNames[p], plots[p].data(), int(plots[p].size()), 0, nullptr, 0.0f, FLT_MAX, ImVec2(0, p ? 30 : 60));
      ImGui::Separator();
      const char* backends[] = {"cpu", "cuda"};
      ImGui::Combo("backend", &settings.backend, backends, options.cudaAvailable ? 2 : 1);
      ImGui::SliderInt("photons 2^n x 2^n", &settings.photonsLog2, 4, 10);
      ImGui::SliderFloat("radius", &settings.radius, 0.005f, 0.2f, "%.3f", ImGuiSliderFlags_Logarithmic);
      const char* maps[] = {"hashgrid", "kdtree"};
      ImGui::Combo("map", &settings.map, maps, 2);
      const char* estimators[] = {"radius", "knn"};
      ImGui::Combo("estimator", &settings.estimator, estimators, 2);
      if (settings.estimator == 1) ImGui::SliderInt("k", &settings.k, 1, 64);
      ImGui::Checkbox("clip the disc at walls and edges", &settings.clippedBoundary);
      ImGui::Combo("GPU kernel", &settings.kernel, kKernels, 4);
      ImGui::Combo("stereo", &settings.stereo, kStereo, 3);
      ImGui::Checkbox("foveated", &settings.foveated);
      const char* acuities[] = {"linear", "geisler-perry"};
      if (settings.foveated) ImGui::Combo("acuity", &settings.acuity, acuities, 2);
      ImGui::Checkbox("TAA", &settings.taa);
      if (settings.taa) ImGui::SliderFloat("TAA blend", &settings.taaBlend, 0.02f, 1.0f);
      ImGui::Checkbox("denoise", &settings.denoise);
      ImGui::Checkbox("raster pre-pass", &settings.rasterPrimary);
      static const char* effectNames[] = {"per material", "raster", "shadows", "reflections", "gi", "path"};
      ImGui::Combo("effects", &settings.effects, effectNames, 1 + kEffectLevels);
      ImGui::SliderFloat("exposure", &settings.exposure, 0.1f, 8.0f, "%.2f", ImGuiSliderFlags_Logarithmic);
      ImGui::Checkbox("both eyes (Tab)", &settings.bothEyes);
      ImGui::Separator();
      ImGui::TextWrapped("Right-drag: look. WASD/QE: move. Cursor: gaze. F12: screenshot + settings. R: reset. Esc: quit.");
      for (const std::string& w : written) ImGui::TextWrapped("wrote %s", w.c_str());
      ImGui::PopItemWidth();
      ImGui::End();
    }
    ImGui::Render();
  }

  void screenshot() {
    std::string prefix = options.screenshotPrefix + (screenshotCount ? "_" + std::to_string(screenshotCount) : "");
    ++screenshotCount;
    std::filesystem::path parent = std::filesystem::path(prefix).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    transfer->waitIdle();
    const char* names[2] = {"left", "right"};
    for (int e = 0; e < 2; ++e) {
      std::vector<unsigned char> rgba = readImage(*vk, eyes[e].image, VK_IMAGE_ASPECT_COLOR_BIT, rig.width, rig.height, 4,
                                                  VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
      std::vector<unsigned char> rgb(size_t(rig.width) * rig.height * 3);
      for (size_t i = 0; i < rgb.size() / 3; ++i)
        for (int c = 0; c < 3; ++c) rgb[3 * i + c] = rgba[4 * i + c];
      std::string path = prefix + "_" + names[e] + ".png";
      writePngRgb(rgb, rig.width, rig.height, path);
      written.push_back(path);
    }
    if (options.writeSettings && lastRequest) {
      std::string path = prefix + ".json";
      options.writeSettings(path, settings, *lastRequest);
      written.push_back(path);
    }
    for (size_t i = written.size() - (options.writeSettings ? 3 : 2); i < written.size(); ++i)
      std::printf("wrote %s\n", written[i].c_str());
  }

  void windowShot(uint32_t index) {  // the whole window, panel included (for the README)
    if (!swapReadable) return;
    std::vector<unsigned char> pixels = readImage(*vk, swapImages[index], VK_IMAGE_ASPECT_COLOR_BIT, int(extent.width),
                                                  int(extent.height), 4, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
    const bool bgr = swapFormat == VK_FORMAT_B8G8R8A8_SRGB || swapFormat == VK_FORMAT_B8G8R8A8_UNORM;
    std::vector<unsigned char> rgb(size_t(extent.width) * extent.height * 3);
    for (size_t i = 0; i < rgb.size() / 3; ++i)
      for (int c = 0; c < 3; ++c) rgb[3 * i + c] = pixels[4 * i + (bgr ? 2 - c : c)];
    std::string path = options.screenshotPrefix + (screenshotCount > 1 ? "_" + std::to_string(screenshotCount - 1) : "") + "_window.png";
    writePngRgb(rgb, int(extent.width), int(extent.height), path);
    written.push_back(path);
    std::printf("wrote %s\n", path.c_str());
  }
};

ViewerPresenter::ViewerPresenter(const StereoRig& rig, const ViewerSettings& settings, const ViewerOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.rig = rig;
  m.settings = m.applied = settings;
  m.options = options;
  m.position = rig.head.position;
  m.start = rig.head.orientation;
  glfwSetErrorCallback([](int, const char*) {});
  if (!glfwInit()) throw Error("cannot open a window: no display (set DISPLAY, or run under xvfb-run)");
  if (!glfwVulkanSupported()) {
    glfwTerminate();
    throw Error("cannot open a window: no Vulkan loader or driver for it (install libvulkan1 and mesa-vulkan-drivers)");
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  int w = options.windowWidth > 0 ? options.windowWidth : rig.width * 2 + (options.panel ? kPanelWidth : 0);
  int h = options.windowHeight > 0 ? options.windowHeight : std::max(rig.height, options.panel ? 560 : 0);
  m.window = glfwCreateWindow(w, h, "photonvr", nullptr, nullptr);
  if (!m.window) {
    glfwTerminate();
    throw Error("cannot open a " + std::to_string(w) + "x" + std::to_string(h) + " window");
  }
  try {
    uint32_t count = 0;
    const char** required = glfwGetRequiredInstanceExtensions(&count);
    VulkanContextOptions vo;
    vo.instanceExtensions.assign(required, required + count);
    vo.deviceExtensions = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
#ifdef PVR_HAVE_CUDA
    vo.hasPreferredUuid = cuda::currentDeviceUuid(vo.preferredUuid);
#endif
    m.vk = std::make_unique<VulkanContext>(vo);
    vkCheck(glfwCreateWindowSurface(m.vk->instance(), m.window, nullptr, &m.surface), "glfwCreateWindowSurface");
    VkBool32 canPresent = VK_FALSE;
    vkGetPhysicalDeviceSurfaceSupportKHR(m.vk->physicalDevice(), m.vk->queueFamily(), m.surface, &canPresent);
    if (!canPresent) throw Error("the Vulkan device '" + m.vk->deviceName() + "' cannot present to this window");
    m.createSwapchain();
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = m.vk->commandPool();
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    vkCheck(vkAllocateCommandBuffers(m.vk->device(), &ai, &m.cmd), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    fci.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    vkCheck(vkCreateFence(m.vk->device(), &fci, nullptr, &m.frameFence), "vkCreateFence");
    VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    vkCheck(vkCreateSemaphore(m.vk->device(), &sci, nullptr, &m.imageAvailable), "vkCreateSemaphore");
    m.makeEyes(false);

    VkDescriptorPoolSize sizes[] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 16}};
    VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dpci.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
    dpci.maxSets = 16;
    dpci.poolSizeCount = 1;
    dpci.pPoolSizes = sizes;
    vkCheck(vkCreateDescriptorPool(m.vk->device(), &dpci, nullptr, &m.imguiPool), "vkCreateDescriptorPool");
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini next to the user's files
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForVulkan(m.window, true);
    ImGui_ImplVulkan_InitInfo ii{};
    ii.Instance = m.vk->instance();
    ii.PhysicalDevice = m.vk->physicalDevice();
    ii.Device = m.vk->device();
    ii.QueueFamily = m.vk->queueFamily();
    ii.Queue = m.vk->queue();
    ii.DescriptorPool = m.imguiPool;
    ii.MinImageCount = 2;
    ii.ImageCount = uint32_t(std::max<size_t>(m.swapImages.size(), 2));
    ii.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
    ii.CheckVkResultFn = checkVk;
    ImGui_ImplVulkan_Init(&ii, m.renderPass);
    m.vk->runOnce([](VkCommandBuffer c) { ImGui_ImplVulkan_CreateFontsTexture(c); });
    ImGui_ImplVulkan_DestroyFontUploadObjects();
    m.imguiReady = true;
    glfwSetWindowUserPointer(m.window, &m);
    glfwSetKeyCallback(m.window, [](GLFWwindow* w, int key, int scancode, int action, int mods) {
      ImGui_ImplGlfw_KeyCallback(w, key, scancode, action, mods);
      if (action == GLFW_PRESS && !ImGui::GetIO().WantCaptureKeyboard) static_cast<Impl*>(glfwGetWindowUserPointer(w))->pressKey(key);
    });
  } catch (...) {
    m.shutdown();
    throw;
  }
}

ViewerPresenter::~ViewerPresenter() { impl_->shutdown(); }

void ViewerPresenter::Impl::shutdown() {
  Impl& m = *this;
  if (m.vk) {
    vkDeviceWaitIdle(m.vk->device());
    if (m.imguiReady) {
      ImGui_ImplVulkan_Shutdown();
      ImGui_ImplGlfw_Shutdown();
      ImGui::DestroyContext();
    }
    m.transfer.reset();
    for (VulkanImage& e : m.eyes) e = VulkanImage();
    m.destroySwapchain();
    if (m.renderPass) vkDestroyRenderPass(m.vk->device(), m.renderPass, nullptr);
    if (m.imguiPool) vkDestroyDescriptorPool(m.vk->device(), m.imguiPool, nullptr);
    if (m.frameFence) vkDestroyFence(m.vk->device(), m.frameFence, nullptr);
    if (m.imageAvailable) vkDestroySemaphore(m.vk->device(), m.imageAvailable, nullptr);
    if (m.surface) vkDestroySurfaceKHR(m.vk->instance(), m.surface, nullptr);
    m.vk.reset();
  }
  if (m.window) glfwDestroyWindow(m.window);
  m.window = nullptr;
  glfwTerminate();
}

FrameOutput ViewerPresenter::output(const Renderer& renderer) const {
  Impl& m = *impl_;
  const bool wantShared = renderer.backendName() == "cuda" && m.vk->canShareWithCuda();
  if (wantShared != (m.transfer->options().path == HandOverPath::CudaShared)) m.makeEyes(wantShared);
  return wantShared ? FrameOutput::DeviceBuffers : FrameOutput::HostImages;
}

bool ViewerPresenter::waitFrame(FrameRequest& request) {
  Impl& m = *impl_;
  glfwPollEvents();
  for (const ScriptedKey& k : m.options.script)
    if (k.frame == m.frame) m.pressKey(k.key);
  if (m.stop || glfwWindowShouldClose(m.window)) return false;
  if (m.backendChange) return false;
  // The monitor the window is on is not tracked: the primary one's refresh is the display period.
  if (GLFWmonitor* monitor = glfwGetPrimaryMonitor()) {
    const GLFWvidmode* mode = glfwGetVideoMode(monitor);
    if (mode && mode->refreshRate > 0) request.displayPeriodMs = 1000.0 / double(mode->refreshRate);
  }
  auto now = std::chrono::steady_clock::now();
  float dt = std::min(std::chrono::duration<float>(now - m.lastFrame).count(), 0.1f);
  m.lastFrame = now;
  const ImGuiIO& io = ImGui::GetIO();
  double x = 0, y = 0;
  glfwGetCursorPos(m.window, &x, &y);
  const bool overPanel = io.WantCaptureMouse;
  if (glfwGetMouseButton(m.window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS && !overPanel) {
    if (m.dragging) {
      m.yaw -= float(x - m.lastX) * 0.004f;
      m.pitch = std::clamp(m.pitch - float(y - m.lastY) * 0.004f, -1.5f, 1.5f);
    }
    m.dragging = true;
  } else {
    m.dragging = false;
  }
  m.lastX = x, m.lastY = y;
  Quat q = m.orientation();
  if (!io.WantCaptureKeyboard) {
    Vec3 move(0.0f);
    if (glfwGetKey(m.window, GLFW_KEY_W) == GLFW_PRESS) move = move + Vec3(0, 0, -1);
    if (glfwGetKey(m.window, GLFW_KEY_S) == GLFW_PRESS) move = move + Vec3(0, 0, 1);
    if (glfwGetKey(m.window, GLFW_KEY_A) == GLFW_PRESS) move = move + Vec3(-1, 0, 0);
    if (glfwGetKey(m.window, GLFW_KEY_D) == GLFW_PRESS) move = move + Vec3(1, 0, 0);
    if (glfwGetKey(m.window, GLFW_KEY_E) == GLFW_PRESS) move = move + Vec3(0, 1, 0);
    if (glfwGetKey(m.window, GLFW_KEY_Q) == GLFW_PRESS) move = move + Vec3(0, -1, 0);
    m.position = m.position + q.rotate(move) * (m.options.moveSpeed * dt);
  }
  // The gaze follows the cursor over an eye image (as fractions of the left eye's image).
  if (!overPanel && x >= 0 && y >= 0) {
    double eyeX = std::fmod(x, double(m.rig.width));
    if (x < (m.settings.bothEyes ? 2.0 : 1.0) * m.rig.width && y < m.rig.height)
      m.gaze[0] = float(eyeX / m.rig.width), m.gaze[1] = float(y / m.rig.height);
  }
  request.rig = m.rig;
  request.rig.head.orientation = q;
  request.rig.head.position = m.position;
  request.gaze[0][0] = request.gaze[1][0] = m.gaze[0];
  request.gaze[0][1] = request.gaze[1][1] = m.gaze[1];
  request.verge = true;
  request.shouldRender = true;
  request.deadline.reset();  // the window's FIFO pacing is the deadline; none is counted
  m.lastRequest = request;
  ++m.frame;
  return true;
}

void ViewerPresenter::adjustOptions(RenderOptions& o) {
  // Only what the panel changed since the last frame: the command line's options (a photon count
  // that is no power of two, a --mask file) stay until their control is touched.
  Impl& m = *impl_;
  const ViewerSettings& s = m.settings;
  ViewerSettings& a = m.applied;
  if (s.photonsLog2 != a.photonsLog2) o.photonsX = o.photonsY = 1u << s.photonsLog2;
  if (s.radius != a.radius) o.gather.density.radius = s.radius;
  if (s.map != a.map) o.map = s.map ? PhotonMapKind::KdTree : PhotonMapKind::HashGrid;
  if (s.estimator != a.estimator) o.gather.density.estimator = s.estimator ? Estimator::Knn : Estimator::Radius;
  if (s.k != a.k) o.gather.density.k = s.k;
  if (s.clippedBoundary != a.clippedBoundary) o.gather.density.boundary = s.clippedBoundary ? Boundary::Clipped : Boundary::Sphere;
  const DensityKernel kernels[] = {DensityKernel::Single, DensityKernel::Hybrid, DensityKernel::SharedMemory, DensityKernel::CellSorted};
  if (s.kernel != a.kernel) o.kernel = kernels[std::clamp(s.kernel, 0, 3)];
  const StereoMode modes[] = {StereoMode::Separate, StereoMode::Scatter, StereoMode::Gather};
  if (s.stereo != a.stereo) o.stereo = modes[std::clamp(s.stereo, 0, 2)];
  o.eyes[0] = true;
  o.eyes[1] = s.bothEyes;
  if (s.taa != a.taa) o.temporal.enabled = s.taa;
  if (s.taaBlend != a.taaBlend) o.temporal.taa.blend = s.taaBlend;
  if (s.denoise != a.denoise) o.denoise.enabled = s.denoise;
  if (s.effects != a.effects) {
    o.gather.overrideEffects = s.effects > 0;
    o.gather.effects = EffectLevel(std::clamp(s.effects - 1, 0, kEffectLevels - 1));
  }
  if (s.rasterPrimary != a.rasterPrimary) o.primary = s.rasterPrimary ? PrimaryVisibility::Raster : PrimaryVisibility::Rays;
  if (s.foveated != a.foveated || (s.foveated && s.acuity != a.acuity)) {
    if (s.foveated) {
      MaskParams params = maskParamsForRig(m.rig);
      params.acuity.kind = s.acuity ? AcuityKind::GeislerPerry : AcuityKind::LinearMar;
      m.mask = generateFoveationMask(params);
      o.foveation.mask = &*m.mask;
    } else {
      o.foveation.mask = nullptr;
    }
  }
  m.transfer->setExposure(s.exposure);
  if (s.backend != a.backend) m.backendChange = true;
  a = s;
}

void ViewerPresenter::present(const PresentedFrame& frame) {
  Impl& m = *impl_;
  if (frame.result) {
    const StageTimings& t = frame.result->timings;
    const float values[5] = {float(t.totalMs()), float(t.photonTraceMs), float(t.mapBuildMs), float(t.eyeMs[0]), float(t.eyeMs[1])};
    for (int p = 0; p < 5; ++p) {
      m.plots[p].push_back(values[p]);
      if (m.plots[p].size() > kPlotFrames) m.plots[p].erase(m.plots[p].begin());
    }
    EyeSource sources[2];
    EyeTarget targets[2];
    for (int e = 0; e < 2; ++e) {
      if (e == 1 && !frame.renderer.options().eyes[1]) continue;
      sources[e] = eyeSourceOf(frame, Eye(e));
      targets[e] = {m.eyes[e].image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
    }
    m.transfer->handOver(sources, targets);
  }
  if (m.screenshotRequested) {
    m.screenshot();
    m.screenshotRequested = false;
    m.windowShotPending = true;  // the window as shown this frame, panel included
  }
  if (!m.swapchain) m.createSwapchain();
  if (!m.swapchain) return;  // minimized
  vkCheck(vkWaitForFences(m.vk->device(), 1, &m.frameFence, VK_TRUE, 5'000'000'000ull), "vkWaitForFences (window)");
  uint32_t index = 0;
  VkResult r = vkAcquireNextImageKHR(m.vk->device(), m.swapchain, 5'000'000'000ull, m.imageAvailable, VK_NULL_HANDLE, &index);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) {  // resized: the next frame uses a new swapchain
    m.destroySwapchain();
    m.createSwapchain();
    return;
  }
  if (r == VK_TIMEOUT) throw Error("the window's swapchain gave no image within 5 s");
  if (r != VK_SUBOPTIMAL_KHR) vkCheck(r, "vkAcquireNextImageKHR");
  vkCheck(vkResetFences(m.vk->device(), 1, &m.frameFence), "vkResetFences");
  m.drawPanel(&frame);
  VkCommandBuffer cmd = m.cmd;
  vkCheck(vkResetCommandBuffer(cmd, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkCheck(vkBeginCommandBuffer(cmd, &bi), "vkBeginCommandBuffer");
  VkImage target = m.swapImages[index];
  transitionImage(cmd, target, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
  VkClearColorValue grey{{0.02f, 0.02f, 0.025f, 1.0f}};
  VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdClearColorImage(cmd, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &grey, 1, &range);
  // Each eye at its size (scaled down to fit when the window is smaller), side by side.
  const int eyesShown = m.settings.bothEyes ? 2 : 1;
  const float room = float(int(m.extent.width) - (m.options.panel ? kPanelWidth : 0));
  const float scale = std::min({1.0f, room / float(eyesShown * m.rig.width), float(m.extent.height) / float(m.rig.height)});
  for (int e = 0; e < eyesShown && scale > 0; ++e) {
    VkImageBlit blit{};
    blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    blit.srcOffsets[1] = {m.rig.width, m.rig.height, 1};
    blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    int x0 = int(std::lround(e * m.rig.width * scale));
    blit.dstOffsets[0] = {x0, 0, 0};
    blit.dstOffsets[1] = {x0 + std::max(1, int(std::lround(m.rig.width * scale))), std::max(1, int(std::lround(m.rig.height * scale))), 1};
    vkCmdBlitImage(cmd, m.eyes[e].image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                   &blit, scale == 1.0f ? VK_FILTER_NEAREST : VK_FILTER_LINEAR);
  }
  transitionImage(cmd, target, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
  VkRenderPassBeginInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  rp.renderPass = m.renderPass;
  rp.framebuffer = m.framebuffers[index];
  rp.renderArea.extent = m.extent;
  vkCmdBeginRenderPass(cmd, &rp, VK_SUBPASS_CONTENTS_INLINE);
  ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd);
  vkCmdEndRenderPass(cmd);
  const bool windowShot = m.windowShotPending && m.swapReadable;
  if (!windowShot)
    transitionImage(cmd, target, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR);
  vkCheck(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
  VkPipelineStageFlags waitStage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.waitSemaphoreCount = 1;
  si.pWaitSemaphores = &m.imageAvailable;
  si.pWaitDstStageMask = &waitStage;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  si.signalSemaphoreCount = windowShot ? 0 : 1;
  si.pSignalSemaphores = &m.renderFinished[index];
  vkCheck(queueSubmit(m.vk->queue(), 1, &si, m.frameFence), "vkQueueSubmit (window)");
  VkSemaphore presentWait = m.renderFinished[index];
  if (windowShot) {  // read the window back before it is presented, then hand it on
    vkCheck(vkWaitForFences(m.vk->device(), 1, &m.frameFence, VK_TRUE, 5'000'000'000ull), "vkWaitForFences (window)");
    m.windowShot(index);
    m.vk->runOnce([&](VkCommandBuffer c) {
      transitionImage(c, target, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR);
    });
    presentWait = VK_NULL_HANDLE;
  }
  VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  pi.waitSemaphoreCount = presentWait ? 1 : 0;
  pi.pWaitSemaphores = &presentWait;
  pi.swapchainCount = 1;
  pi.pSwapchains = &m.swapchain;
  pi.pImageIndices = &index;
  m.windowShotPending = false;
  r = vkQueuePresentKHR(m.vk->queue(), &pi);
  if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) {
    m.destroySwapchain();
    m.createSwapchain();
  } else {
    vkCheck(r, "vkQueuePresentKHR");
  }
}

void ViewerPresenter::requestStop() { impl_->stop = true; }
bool ViewerPresenter::backendChangeRequested() const { return impl_->backendChange; }
void ViewerPresenter::clearBackendChange() { impl_->backendChange = false; }
const ViewerSettings& ViewerPresenter::settings() const { return impl_->settings; }
std::vector<std::string> ViewerPresenter::screenshotsWritten() const { return impl_->written; }

}  // namespace pvr
