// A tiny OpenXR runtime for tests: just enough of the API for photonvr's XrPresenter to run a
// session on any Vulkan device (lavapipe in CI), and failure modes chosen by PVR_FAKE_XR so that
// each of photonvr's OpenXR errors can be provoked:
//   ok (default) | noext (no XR_KHR_vulkan_enable2) | nohmd (no headset) | binding (the graphics
//   binding is refused) | formats (no usable swapchain format) | noready (READY never comes) |
//   lost (LOSS_PENDING after 5 frames) | norelease (swapchain images are never released) |
//   nocontrollers (no controller profile's bindings are taken) | unfocus (the session loses focus,
//   VISIBLE, at frame 4 and has it back at frame 8; xrSyncActions answers XR_SESSION_NOT_FOCUSED
//   in between)
// Input: actions with a khr/simple_controller in each hand. PVR_FAKE_XR_PRESS holds the buttons
// down, "FRAME:PATH,..." (e.g. "3:/user/hand/right/input/select/click"): that input path is down
// for the frame FRAME (counted by xrWaitFrame from 1); a path on successive frames is held.
// The loader finds it through XR_RUNTIME_JSON. The negotiation structs are declared here from the
// OpenXR loader specification (Debian's headers do not ship them).
#include <vulkan/vulkan.h>
#define XR_USE_GRAPHICS_API_VULKAN
#define XR_USE_TIMESPEC
#include <time.h>
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <iterator>
#include <map>
#include <string>
#include <vector>

namespace {

enum LoaderInterfaceStruct { kUninitialized = 0, kLoaderInfo = 1, kApiLayerRequest = 2, kRuntimeRequest = 3 };
struct NegotiateLoaderInfo {
  LoaderInterfaceStruct structType;
  uint32_t structVersion;
  size_t structSize;
  uint32_t minInterfaceVersion, maxInterfaceVersion;
  XrVersion minApiVersion, maxApiVersion;
};
struct NegotiateRuntimeRequest {
  LoaderInterfaceStruct structType;
  uint32_t structVersion;
  size_t structSize;
  uint32_t runtimeInterfaceVersion;
  XrVersion runtimeApiVersion;
  PFN_xrGetInstanceProcAddr getInstanceProcAddr;
};

std::string mode() {
  const char* m = std::getenv("PVR_FAKE_XR");
  return m ? m : "ok";
}

struct Swapchain {
  std::vector<VkImage> images;
  std::vector<VkDeviceMemory> memory;
  uint32_t next = 0;
};

struct Action {
  XrActionType type;
  uint64_t set;
  std::vector<XrPath> bindings;  // on the simple controller
  bool down = false, changed = false;
};

struct State {
  std::vector<std::string> paths = {""};  // XrPath n is paths[n]; 0 is XR_NULL_PATH
  std::map<uint64_t, Action> actions;
  std::map<uint64_t, bool> actionSets;  // attached?
  bool attached = false;
  int waitedFrames = 0;
  VkInstance vkInstance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  std::deque<XrSessionState> events;
  std::map<uint64_t, Swapchain> swapchains;
  uint64_t nextHandle = 16;
  int frames = 0;
  bool lossSent = false;
  bool unfocused = false;
} g;

XrTime nowNs() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return XrTime(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

template <class T>
XrResult fill(uint32_t capacity, uint32_t* count, T* out, const std::vector<T>& items) {
  *count = uint32_t(items.size());
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < items.size()) return XR_ERROR_SIZE_INSUFFICIENT;
  for (size_t i = 0; i < items.size(); ++i) out[i] = items[i];
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL enumerateExtensions(const char*, uint32_t capacity, uint32_t* count, XrExtensionProperties* props) {
  std::vector<const char*> names = {XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME, XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME};
  if (mode() != "noext") names.push_back(XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME);
  *count = uint32_t(names.size());
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < names.size()) return XR_ERROR_SIZE_INSUFFICIENT;
  for (size_t i = 0; i < names.size(); ++i) {
    std::strncpy(props[i].extensionName, names[i], XR_MAX_EXTENSION_NAME_SIZE - 1);
    props[i].extensionVersion = 1;
  }
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL createInstance(const XrInstanceCreateInfo* info, XrInstance* instance) {
  for (uint32_t i = 0; i < info->enabledExtensionCount; ++i)
    if (mode() == "noext" && std::strcmp(info->enabledExtensionNames[i], XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME) == 0)
      return XR_ERROR_EXTENSION_NOT_PRESENT;
  g = State();
  *instance = reinterpret_cast<XrInstance>(uintptr_t(1));
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL destroyInstance(XrInstance) { return XR_SUCCESS; }

XRAPI_ATTR XrResult XRAPI_CALL getInstanceProperties(XrInstance, XrInstanceProperties* p) {
  std::strcpy(p->runtimeName, "photonvr test runtime");
  p->runtimeVersion = XR_MAKE_VERSION(0, 1, 0);
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL getSystem(XrInstance, const XrSystemGetInfo*, XrSystemId* id) {
  if (mode() == "nohmd") return XR_ERROR_FORM_FACTOR_UNAVAILABLE;
  *id = 1;
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL getSystemProperties(XrInstance, XrSystemId, XrSystemProperties* p) {
  std::strcpy(p->systemName, "test HMD");
  p->graphicsProperties.maxSwapchainImageWidth = p->graphicsProperties.maxSwapchainImageHeight = 4096;
  p->trackingProperties.orientationTracking = p->trackingProperties.positionTracking = XR_TRUE;
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL enumerateViewConfigurationViews(XrInstance, XrSystemId, XrViewConfigurationType, uint32_t capacity,
                                                               uint32_t* count, XrViewConfigurationView* views) {
  *count = 2;
  if (capacity == 0) return XR_SUCCESS;
  for (int i = 0; i < 2; ++i) {
    views[i].recommendedImageRectWidth = 64, views[i].recommendedImageRectHeight = 48;
    views[i].maxImageRectWidth = views[i].maxImageRectHeight = 4096;
    views[i].recommendedSwapchainSampleCount = views[i].maxSwapchainSampleCount = 1;
  }
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL enumerateBlendModes(XrInstance, XrSystemId, XrViewConfigurationType, uint32_t capacity, uint32_t* count,
                                                   XrEnvironmentBlendMode* modes) {
  return fill(capacity, count, modes, std::vector<XrEnvironmentBlendMode>{XR_ENVIRONMENT_BLEND_MODE_OPAQUE});
}

XRAPI_ATTR XrResult XRAPI_CALL graphicsRequirements(XrInstance, XrSystemId, XrGraphicsRequirementsVulkanKHR* r) {
  r->minApiVersionSupported = XR_MAKE_VERSION(1, 0, 0);
  r->maxApiVersionSupported = XR_MAKE_VERSION(1, 3, 0);
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL createVulkanInstance(XrInstance, const XrVulkanInstanceCreateInfoKHR* info, VkInstance* out, VkResult* vr) {
  *vr = vkCreateInstance(info->vulkanCreateInfo, nullptr, out);
  g.vkInstance = *out;
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL graphicsDevice(XrInstance, const XrVulkanGraphicsDeviceGetInfoKHR* info, VkPhysicalDevice* out) {
  uint32_t n = 1;
  VkPhysicalDevice first = VK_NULL_HANDLE;
  VkResult r = vkEnumeratePhysicalDevices(info->vulkanInstance, &n, &first);
  if ((r != VK_SUCCESS && r != VK_INCOMPLETE) || !first) return XR_ERROR_RUNTIME_FAILURE;
  *out = g.physical = first;
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL createVulkanDevice(XrInstance, const XrVulkanDeviceCreateInfoKHR* info, VkDevice* out, VkResult* vr) {
  *vr = vkCreateDevice(info->vulkanPhysicalDevice, info->vulkanCreateInfo, nullptr, out);
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL createSession(XrInstance, const XrSessionCreateInfo* info, XrSession* session) {
  if (mode() == "binding") return XR_ERROR_GRAPHICS_DEVICE_INVALID;
  auto* binding = static_cast<const XrGraphicsBindingVulkan2KHR*>(info->next);
  if (!binding || binding->type != XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR) return XR_ERROR_GRAPHICS_DEVICE_INVALID;
  g.device = binding->device;
  g.events = {XR_SESSION_STATE_IDLE};
  if (mode() != "noready") g.events.push_back(XR_SESSION_STATE_READY);
  *session = reinterpret_cast<XrSession>(uintptr_t(2));
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL destroySession(XrSession) { return XR_SUCCESS; }

XRAPI_ATTR XrResult XRAPI_CALL createReferenceSpace(XrSession, const XrReferenceSpaceCreateInfo*, XrSpace* space) {
  *space = reinterpret_cast<XrSpace>(uintptr_t(g.nextHandle++));
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL destroySpace(XrSpace) { return XR_SUCCESS; }

XRAPI_ATTR XrResult XRAPI_CALL enumerateSwapchainFormats(XrSession, uint32_t capacity, uint32_t* count, int64_t* formats) {
  if (mode() == "formats")
    return fill(capacity, count, formats, std::vector<int64_t>{VK_FORMAT_BC1_RGB_UNORM_BLOCK, VK_FORMAT_A2B10G10R10_UNORM_PACK32});
  return fill(capacity, count, formats, std::vector<int64_t>{VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_D32_SFLOAT});
}

XRAPI_ATTR XrResult XRAPI_CALL createSwapchain(XrSession, const XrSwapchainCreateInfo* info, XrSwapchain* out) {
  Swapchain s;
  const bool depth = info->format == VK_FORMAT_D32_SFLOAT;
  VkPhysicalDeviceMemoryProperties memory;
  vkGetPhysicalDeviceMemoryProperties(g.physical, &memory);
  for (int i = 0; i < 3; ++i) {
    VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = VkFormat(info->format);
    ici.extent = {info->width, info->height, 1};
    ici.mipLevels = ici.arrayLayers = 1;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.tiling = VK_IMAGE_TILING_OPTIMAL;
    ici.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                (depth ? VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT : VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
    VkImage image;
    if (vkCreateImage(g.device, &ici, nullptr, &image) != VK_SUCCESS) return XR_ERROR_RUNTIME_FAILURE;
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(g.device, image, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    for (uint32_t t = 0; t < memory.memoryTypeCount; ++t)
      if (req.memoryTypeBits & (1u << t)) {
        mai.memoryTypeIndex = t;
        break;
      }
    VkDeviceMemory mem;
    if (vkAllocateMemory(g.device, &mai, nullptr, &mem) != VK_SUCCESS) return XR_ERROR_OUT_OF_MEMORY;
    vkBindImageMemory(g.device, image, mem, 0);
    s.images.push_back(image);
    s.memory.push_back(mem);
  }
  uint64_t handle = g.nextHandle++;
  g.swapchains[handle] = s;
  *out = reinterpret_cast<XrSwapchain>(uintptr_t(handle));
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL destroySwapchain(XrSwapchain swapchain) {
  auto it = g.swapchains.find(uint64_t(reinterpret_cast<uintptr_t>(swapchain)));
  if (it == g.swapchains.end()) return XR_ERROR_HANDLE_INVALID;
  vkDeviceWaitIdle(g.device);
  for (size_t i = 0; i < it->second.images.size(); ++i) {
    vkDestroyImage(g.device, it->second.images[i], nullptr);
    vkFreeMemory(g.device, it->second.memory[i], nullptr);
  }
  g.swapchains.erase(it);
  return XR_SUCCESS;
}

Swapchain* find(XrSwapchain swapchain) {
  auto it = g.swapchains.find(uint64_t(reinterpret_cast<uintptr_t>(swapchain)));
  return it == g.swapchains.end() ? nullptr : &it->second;
}

XRAPI_ATTR XrResult XRAPI_CALL enumerateSwapchainImages(XrSwapchain swapchain, uint32_t capacity, uint32_t* count,
                                                        XrSwapchainImageBaseHeader* images) {
  Swapchain* s = find(swapchain);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  *count = uint32_t(s->images.size());
  if (capacity == 0) return XR_SUCCESS;
  auto* vk = reinterpret_cast<XrSwapchainImageVulkan2KHR*>(images);
  for (size_t i = 0; i < s->images.size() && i < capacity; ++i) vk[i].image = s->images[i];
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL acquireImage(XrSwapchain swapchain, const XrSwapchainImageAcquireInfo*, uint32_t* index) {
  Swapchain* s = find(swapchain);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  *index = s->next;
  s->next = (s->next + 1) % uint32_t(s->images.size());
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL waitImage(XrSwapchain, const XrSwapchainImageWaitInfo*) {
  return mode() == "norelease" ? XR_TIMEOUT_EXPIRED : XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL releaseImage(XrSwapchain, const XrSwapchainImageReleaseInfo*) { return XR_SUCCESS; }

XRAPI_ATTR XrResult XRAPI_CALL pollEvent(XrInstance, XrEventDataBuffer* event) {
  if (g.events.empty()) return XR_EVENT_UNAVAILABLE;
  auto* changed = reinterpret_cast<XrEventDataSessionStateChanged*>(event);
  changed->type = XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED;
  changed->next = nullptr;
  changed->session = reinterpret_cast<XrSession>(uintptr_t(2));
  changed->state = g.events.front();
  changed->time = nowNs();
  g.events.pop_front();
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL beginSession(XrSession, const XrSessionBeginInfo*) {
  for (XrSessionState s : {XR_SESSION_STATE_SYNCHRONIZED, XR_SESSION_STATE_VISIBLE, XR_SESSION_STATE_FOCUSED}) g.events.push_back(s);
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL requestExit(XrSession) {
  for (XrSessionState s : {XR_SESSION_STATE_VISIBLE, XR_SESSION_STATE_SYNCHRONIZED, XR_SESSION_STATE_STOPPING}) g.events.push_back(s);
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL endSession(XrSession) {
  for (XrSessionState s : {XR_SESSION_STATE_IDLE, XR_SESSION_STATE_EXITING}) g.events.push_back(s);
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL waitFrame(XrSession, const XrFrameWaitInfo*, XrFrameState* state) {
  if (g.lossSent) return XR_ERROR_SESSION_LOST;
  ++g.waitedFrames;
  state->predictedDisplayPeriod = 11'111'111;
  state->predictedDisplayTime = nowNs() + 2 * state->predictedDisplayPeriod;
  state->shouldRender = XR_TRUE;
  if (mode() == "unfocus" && (g.waitedFrames == 4 || g.waitedFrames == 8)) {
    g.unfocused = g.waitedFrames == 4;
    g.events.push_back(g.unfocused ? XR_SESSION_STATE_VISIBLE : XR_SESSION_STATE_FOCUSED);
  }
  if (mode() == "lost" && ++g.frames == 5) {
    g.events.push_back(XR_SESSION_STATE_LOSS_PENDING);
    g.lossSent = true;
  }
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL beginFrame(XrSession, const XrFrameBeginInfo*) { return XR_SUCCESS; }

XRAPI_ATTR XrResult XRAPI_CALL endFrame(XrSession, const XrFrameEndInfo* info) {
  return info->layerCount <= 1 ? XR_SUCCESS : XR_ERROR_LAYER_LIMIT_EXCEEDED;
}

XRAPI_ATTR XrResult XRAPI_CALL locateViews(XrSession, const XrViewLocateInfo*, XrViewState* state, uint32_t capacity, uint32_t* count,
                                           XrView* views) {
  *count = 2;
  if (capacity < 2) return capacity == 0 ? XR_SUCCESS : XR_ERROR_SIZE_INSUFFICIENT;
  state->viewStateFlags = XR_VIEW_STATE_ORIENTATION_VALID_BIT | XR_VIEW_STATE_POSITION_VALID_BIT |
                          XR_VIEW_STATE_ORIENTATION_TRACKED_BIT | XR_VIEW_STATE_POSITION_TRACKED_BIT;
  for (int e = 0; e < 2; ++e) {
    views[e].pose.orientation = {0, 0, 0, 1};
    views[e].pose.position = {e ? 0.032f : -0.032f, 0, 0};
    views[e].fov = {-0.75f, 0.7f, 0.7f, -0.72f};
  }
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL timeToTimespec(XrInstance, XrTime time, timespec* ts) {
  ts->tv_sec = time / 1000000000;
  ts->tv_nsec = time % 1000000000;
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL stringToPath(XrInstance, const char* text, XrPath* path) {
  if (!text || text[0] != '/') return XR_ERROR_PATH_FORMAT_INVALID;
  for (size_t i = 1; i < g.paths.size(); ++i)
    if (g.paths[i] == text) return *path = XrPath(i), XR_SUCCESS;
  g.paths.push_back(text);
  *path = XrPath(g.paths.size() - 1);
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL pathToString(XrInstance, XrPath path, uint32_t capacity, uint32_t* count, char* out) {
  if (path == XR_NULL_PATH || path >= g.paths.size()) return XR_ERROR_PATH_INVALID;
  const std::string& text = g.paths[path];
  *count = uint32_t(text.size() + 1);
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < *count) return XR_ERROR_SIZE_INSUFFICIENT;
  std::memcpy(out, text.c_str(), *count);
  return XR_SUCCESS;
}

std::string pathText(XrPath path) { return path < g.paths.size() ? g.paths[path] : ""; }

XRAPI_ATTR XrResult XRAPI_CALL createActionSet(XrInstance, const XrActionSetCreateInfo* info, XrActionSet* set) {
  if (g.attached) return XR_ERROR_ACTIONSETS_ALREADY_ATTACHED;
  if (!info->actionSetName[0]) return XR_ERROR_NAME_INVALID;
  uint64_t handle = g.nextHandle++;
  g.actionSets[handle] = false;
  *set = reinterpret_cast<XrActionSet>(uintptr_t(handle));
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL destroyActionSet(XrActionSet set) {
  const uint64_t handle = uint64_t(reinterpret_cast<uintptr_t>(set));
  if (!g.actionSets.erase(handle)) return XR_ERROR_HANDLE_INVALID;
  for (auto it = g.actions.begin(); it != g.actions.end();) it = it->second.set == handle ? g.actions.erase(it) : std::next(it);
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL createAction(XrActionSet set, const XrActionCreateInfo* info, XrAction* action) {
  const uint64_t owner = uint64_t(reinterpret_cast<uintptr_t>(set));
  if (!g.actionSets.count(owner)) return XR_ERROR_HANDLE_INVALID;
  if (g.actionSets[owner]) return XR_ERROR_ACTIONSETS_ALREADY_ATTACHED;
  if (!info->actionName[0]) return XR_ERROR_NAME_INVALID;
  uint64_t handle = g.nextHandle++;
  g.actions[handle] = Action{info->actionType, owner, {}};
  *action = reinterpret_cast<XrAction>(uintptr_t(handle));
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL destroyAction(XrAction action) {
  return g.actions.erase(uint64_t(reinterpret_cast<uintptr_t>(action))) ? XR_SUCCESS : XR_ERROR_HANDLE_INVALID;
}

// The OpenXR 1.0 core controller profiles, each with its button inputs (both hands unless the
// path names one) and the poses; a binding to anything else is refused, as a runtime must.
struct Profile {
  const char* path;
  std::vector<std::string> inputs;
};
const std::vector<Profile>& coreProfiles() {
  static const std::vector<Profile> profiles = {
      {"/interaction_profiles/khr/simple_controller", {"select/click", "menu/click"}},
      {"/interaction_profiles/oculus/touch_controller",
       {"left/x/click", "left/y/click", "left/menu/click", "right/a/click", "right/b/click", "squeeze/value", "trigger/value",
        "thumbstick/click"}},
      {"/interaction_profiles/valve/index_controller",
       {"a/click", "b/click", "squeeze/value", "trigger/click", "trigger/value", "thumbstick/click", "trackpad/touch"}},
      {"/interaction_profiles/htc/vive_controller", {"menu/click", "squeeze/click", "trigger/click", "trackpad/click"}},
      {"/interaction_profiles/microsoft/motion_controller",
       {"menu/click", "squeeze/click", "trigger/value", "thumbstick/click", "trackpad/click"}},
  };
  return profiles;
}

bool profileHas(const Profile& profile, const std::string& path) {
  for (const char* hand : {"left", "right"}) {
    const std::string prefix = std::string("/user/hand/") + hand + "/input/";
    if (path.rfind(prefix, 0) != 0) continue;
    const std::string input = path.substr(prefix.size());
    if (input == "grip/pose" || input == "aim/pose") return true;
    for (const std::string& i : profile.inputs)
      if (i == input || i == hand + ("/" + input)) return true;
  }
  return false;
}

// Suggested bindings: the core profiles are taken (the spec requires it), each call replacing the
// profile's earlier suggestions; only the simple controller's take effect, as on a runtime with
// those controllers in hand.
XRAPI_ATTR XrResult XRAPI_CALL suggestBindings(XrInstance, const XrInteractionProfileSuggestedBinding* info) {
  const std::string name = pathText(info->interactionProfile);
  const Profile* profile = nullptr;
  for (const Profile& p : coreProfiles())
    if (name == p.path) profile = &p;
  if (!profile || mode() == "nocontrollers") return XR_ERROR_PATH_UNSUPPORTED;
  if (g.attached) return XR_ERROR_ACTIONSETS_ALREADY_ATTACHED;
  for (uint32_t i = 0; i < info->countSuggestedBindings; ++i) {
    const XrActionSuggestedBinding& b = info->suggestedBindings[i];
    if (!g.actions.count(uint64_t(reinterpret_cast<uintptr_t>(b.action)))) return XR_ERROR_HANDLE_INVALID;
    if (!profileHas(*profile, pathText(b.binding))) return XR_ERROR_PATH_UNSUPPORTED;
  }
  if (profile != &coreProfiles()[0]) return XR_SUCCESS;
  for (auto& [handle, action] : g.actions) action.bindings.clear();
  for (uint32_t i = 0; i < info->countSuggestedBindings; ++i)
    g.actions[uint64_t(reinterpret_cast<uintptr_t>(info->suggestedBindings[i].action))].bindings.push_back(
        info->suggestedBindings[i].binding);
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL attachActionSets(XrSession, const XrSessionActionSetsAttachInfo* info) {
  if (g.attached) return XR_ERROR_ACTIONSETS_ALREADY_ATTACHED;
  for (uint32_t i = 0; i < info->countActionSets; ++i) {
    auto it = g.actionSets.find(uint64_t(reinterpret_cast<uintptr_t>(info->actionSets[i])));
    if (it == g.actionSets.end()) return XR_ERROR_HANDLE_INVALID;
    it->second = true;
  }
  g.attached = true;
  return XR_SUCCESS;
}

// Whether PVR_FAKE_XR_PRESS holds `path` down in the frame waited for last.
bool held(const std::string& path) {
  const char* spec = std::getenv("PVR_FAKE_XR_PRESS");
  std::string list = spec ? spec : "";
  for (size_t start = 0; start < list.size();) {
    size_t end = list.find(',', start);
    if (end == std::string::npos) end = list.size();
    const std::string item = list.substr(start, end - start);
    const size_t colon = item.find(':');
    if (colon != std::string::npos && std::atoi(item.c_str()) == g.waitedFrames && item.substr(colon + 1) == path) return true;
    start = end + 1;
  }
  return false;
}

XRAPI_ATTR XrResult XRAPI_CALL syncActions(XrSession, const XrActionsSyncInfo* info) {
  for (uint32_t i = 0; i < info->countActiveActionSets; ++i) {
    auto it = g.actionSets.find(uint64_t(reinterpret_cast<uintptr_t>(info->activeActionSets[i].actionSet)));
    if (it == g.actionSets.end()) return XR_ERROR_HANDLE_INVALID;
    if (!it->second) return XR_ERROR_ACTIONSET_NOT_ATTACHED;
  }
  if (g.unfocused) return XR_SESSION_NOT_FOCUSED;  // a success code: the states stay as they were
  for (auto& [handle, action] : g.actions) {
    if (action.type != XR_ACTION_TYPE_BOOLEAN_INPUT) continue;
    bool down = false;
    for (XrPath p : action.bindings) down = down || held(pathText(p));
    action.changed = down != action.down;
    action.down = down;
  }
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL getBoolean(XrSession, const XrActionStateGetInfo* info, XrActionStateBoolean* state) {
  auto it = g.actions.find(uint64_t(reinterpret_cast<uintptr_t>(info->action)));
  if (it == g.actions.end()) return XR_ERROR_HANDLE_INVALID;
  if (it->second.type != XR_ACTION_TYPE_BOOLEAN_INPUT) return XR_ERROR_ACTION_TYPE_MISMATCH;
  if (!g.actionSets[it->second.set]) return XR_ERROR_ACTIONSET_NOT_ATTACHED;
  state->isActive = it->second.bindings.empty() ? XR_FALSE : XR_TRUE;
  state->currentState = it->second.down ? XR_TRUE : XR_FALSE;
  state->changedSinceLastSync = it->second.changed ? XR_TRUE : XR_FALSE;
  state->lastChangeTime = nowNs();
  return XR_SUCCESS;
}

XRAPI_ATTR XrResult XRAPI_CALL getInstanceProcAddr(XrInstance, const char* name, PFN_xrVoidFunction* function) {
  static const std::map<std::string, PFN_xrVoidFunction> table = {
#define PVR_FAKE(name, f) {name, reinterpret_cast<PFN_xrVoidFunction>(f)}
      PVR_FAKE("xrGetInstanceProcAddr", getInstanceProcAddr),
      PVR_FAKE("xrEnumerateInstanceExtensionProperties", enumerateExtensions),
      PVR_FAKE("xrCreateInstance", createInstance),
      PVR_FAKE("xrDestroyInstance", destroyInstance),
      PVR_FAKE("xrGetInstanceProperties", getInstanceProperties),
      PVR_FAKE("xrGetSystem", getSystem),
      PVR_FAKE("xrGetSystemProperties", getSystemProperties),
      PVR_FAKE("xrEnumerateViewConfigurationViews", enumerateViewConfigurationViews),
      PVR_FAKE("xrEnumerateEnvironmentBlendModes", enumerateBlendModes),
      PVR_FAKE("xrGetVulkanGraphicsRequirements2KHR", graphicsRequirements),
      PVR_FAKE("xrCreateVulkanInstanceKHR", createVulkanInstance),
      PVR_FAKE("xrGetVulkanGraphicsDevice2KHR", graphicsDevice),
      PVR_FAKE("xrCreateVulkanDeviceKHR", createVulkanDevice),
      PVR_FAKE("xrCreateSession", createSession),
      PVR_FAKE("xrDestroySession", destroySession),
      PVR_FAKE("xrCreateReferenceSpace", createReferenceSpace),
      PVR_FAKE("xrDestroySpace", destroySpace),
      PVR_FAKE("xrEnumerateSwapchainFormats", enumerateSwapchainFormats),
      PVR_FAKE("xrCreateSwapchain", createSwapchain),
      PVR_FAKE("xrDestroySwapchain", destroySwapchain),
      PVR_FAKE("xrEnumerateSwapchainImages", enumerateSwapchainImages),
      PVR_FAKE("xrAcquireSwapchainImage", acquireImage),
      PVR_FAKE("xrWaitSwapchainImage", waitImage),
      PVR_FAKE("xrReleaseSwapchainImage", releaseImage),
      PVR_FAKE("xrPollEvent", pollEvent),
      PVR_FAKE("xrBeginSession", beginSession),
      PVR_FAKE("xrEndSession", endSession),
      PVR_FAKE("xrRequestExitSession", requestExit),
      PVR_FAKE("xrWaitFrame", waitFrame),
      PVR_FAKE("xrBeginFrame", beginFrame),
      PVR_FAKE("xrEndFrame", endFrame),
      PVR_FAKE("xrLocateViews", locateViews),
      PVR_FAKE("xrConvertTimeToTimespecTimeKHR", timeToTimespec),
      PVR_FAKE("xrStringToPath", stringToPath),
      PVR_FAKE("xrPathToString", pathToString),
      PVR_FAKE("xrCreateActionSet", createActionSet),
      PVR_FAKE("xrDestroyActionSet", destroyActionSet),
      PVR_FAKE("xrCreateAction", createAction),
      PVR_FAKE("xrDestroyAction", destroyAction),
      PVR_FAKE("xrSuggestInteractionProfileBindings", suggestBindings),
      PVR_FAKE("xrAttachSessionActionSets", attachActionSets),
      PVR_FAKE("xrSyncActions", syncActions),
      PVR_FAKE("xrGetActionStateBoolean", getBoolean),
#undef PVR_FAKE
  };
  auto it = table.find(name);
  *function = it == table.end() ? nullptr : it->second;
  return it == table.end() ? XR_ERROR_FUNCTION_UNSUPPORTED : XR_SUCCESS;
}

}  // namespace

extern "C" __attribute__((visibility("default"))) XrResult xrNegotiateLoaderRuntimeInterface(const NegotiateLoaderInfo* info,
                                                                                             NegotiateRuntimeRequest* request) {
  if (!info || !request || info->structType != kLoaderInfo || request->structType != kRuntimeRequest)
    return XR_ERROR_INITIALIZATION_FAILED;
  request->runtimeInterfaceVersion = 1;
  request->runtimeApiVersion = XR_CURRENT_API_VERSION;
  request->getInstanceProcAddr = getInstanceProcAddr;
  return XR_SUCCESS;
}
