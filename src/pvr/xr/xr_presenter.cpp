#include "pvr/xr/xr_presenter.h"

#include <vulkan/vulkan.h>
#define XR_USE_GRAPHICS_API_VULKAN
#define XR_USE_TIMESPEC
#include <time.h>
#include <openxr/openxr_platform.h>
#include <openxr/openxr_reflection.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <thread>
#include <vector>

#include "pvr/foveation/gaze.h"
#include "pvr/loop/loop_keys.h"
#include "pvr/util/error.h"
#include "pvr/vk/eye_transfer.h"
#include "pvr/vk/frame_source.h"
#include "pvr/vulkan/vulkan_context.h"
#include "pvr/xr/xr_views.h"
#ifdef PVR_HAVE_CUDA
#include "pvr/cuda/display_handover.h"
#endif

namespace pvr {

const char* xrResultName(XrResult result) {
#define PVR_XR_RESULT_CASE(name, value) \
  case name:                            \
    return #name;
  switch (result) {
    XR_LIST_ENUM_XrResult(PVR_XR_RESULT_CASE)
    default:
      return "XrResult error";
  }
#undef PVR_XR_RESULT_CASE
}

namespace {

void xrCheck(XrResult result, const char* what) {
  if (XR_FAILED(result)) throw Error(std::string("OpenXR: ") + what + " failed (" + xrResultName(result) + ")");
}

template <class F>
F instanceProc(XrInstance instance, const char* name) {
  PFN_xrVoidFunction f = nullptr;
  xrCheck(xrGetInstanceProcAddr(instance, name, &f), name);
  return reinterpret_cast<F>(f);
}

bool hasExtension(const std::vector<XrExtensionProperties>& list, const char* name) {
  return std::any_of(list.begin(), list.end(), [&](const XrExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

const char* formatName(int64_t f) {
  switch (f) {
    case VK_FORMAT_R8G8B8A8_SRGB: return "R8G8B8A8_SRGB";
    case VK_FORMAT_B8G8R8A8_SRGB: return "B8G8R8A8_SRGB";
    case VK_FORMAT_R8G8B8A8_UNORM: return "R8G8B8A8_UNORM";
    case VK_FORMAT_B8G8R8A8_UNORM: return "B8G8R8A8_UNORM";
    case VK_FORMAT_R16G16B16A16_SFLOAT: return "R16G16B16A16_SFLOAT";
    case VK_FORMAT_D32_SFLOAT: return "D32_SFLOAT";
    default: return nullptr;
  }
}

struct Swapchain {
  XrSwapchain handle = XR_NULL_HANDLE;
  std::vector<XrSwapchainImageVulkan2KHR> images;
};

// Where the two effect-level buttons sit on the controllers of the OpenXR 1.0 core profiles: the
// right hand steps to the next level, the other button returns to the scene's own levels. The
// runtime maps whichever controller is in hand onto one of these.
struct ControllerBinding {
  const char *profile, *nextLevel, *sceneLevels;
};
constexpr ControllerBinding kControllerBindings[] = {
    {"/interaction_profiles/khr/simple_controller", "/user/hand/right/input/select/click", "/user/hand/left/input/select/click"},
    {"/interaction_profiles/oculus/touch_controller", "/user/hand/right/input/a/click", "/user/hand/right/input/b/click"},
    {"/interaction_profiles/valve/index_controller", "/user/hand/right/input/a/click", "/user/hand/right/input/b/click"},
    {"/interaction_profiles/htc/vive_controller", "/user/hand/right/input/trackpad/click", "/user/hand/left/input/trackpad/click"},
    {"/interaction_profiles/microsoft/motion_controller", "/user/hand/right/input/trackpad/click",
     "/user/hand/left/input/trackpad/click"},
};

// A boolean action and the loop key its press stands for (pvr/loop/loop_keys.h).
struct Button {
  XrAction action = XR_NULL_HANDLE;
  char key = 0;
  const char* name = "";
};

}  // namespace

struct XrPresenter::Impl {
  XrPresenterOptions options;
  XrInstance instance = XR_NULL_HANDLE;
  XrSystemId system = XR_NULL_SYSTEM_ID;
  XrSession session = XR_NULL_HANDLE;
  XrSpace space = XR_NULL_HANDLE;
  XrEnvironmentBlendMode blend = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  std::unique_ptr<VulkanContext> vulkan;
  std::unique_ptr<EyeTransfer> transfer;
  Swapchain colour[2], depth[2];
  bool depthLayer = false;
  int width = 0, height = 0;
  // Input, in one action set (a session attaches its sets once): the eye gaze pose
  // (XR_EXT_eye_gaze_interaction) and the effect-level buttons.
  XrActionSet inputSet = XR_NULL_HANDLE;
  XrAction gazeAction = XR_NULL_HANDLE;
  XrSpace gazeSpace = XR_NULL_HANDLE;
  int gazeFramesTracked = 0;
  Button buttons[2];
  std::deque<Button> presses;  ///< seen at the frame's sync, applied by adjustOptions
  int controllerPresses = 0;
  bool syncedFocused = false;  ///< the last frame synced the actions (focus held since)
  uint64_t frames = 0;         ///< frames waited for (the one being prepared: frames - 1)
  PFN_xrConvertTimeToTimespecTimeKHR toTimespec = nullptr;
  // The frame in flight
  bool frameBegun = false;
  XrFrameState frameState{XR_TYPE_FRAME_STATE};
  XrView views[2] = {{XR_TYPE_VIEW}, {XR_TYPE_VIEW}};
  bool viewsValid = false;
  LoopClock::time_point waitingSince = LoopClock::now(), stopRequestedAt;

  ~Impl() {
    transfer.reset();  // waits for the copies
    for (Swapchain* s : {&colour[0], &colour[1], &depth[0], &depth[1]})
      if (s->handle) xrDestroySwapchain(s->handle);
    if (gazeSpace) xrDestroySpace(gazeSpace);
    if (inputSet) xrDestroyActionSet(inputSet);  // and its actions
    if (space) xrDestroySpace(space);
    if (session) xrDestroySession(session);
    vulkan.reset();  // made through the runtime: destroyed before the instance that made it
    if (instance) xrDestroyInstance(instance);
  }

  Swapchain makeSwapchain(int64_t format, XrSwapchainUsageFlags usage) {
    XrSwapchainCreateInfo sci{XR_TYPE_SWAPCHAIN_CREATE_INFO};
    sci.usageFlags = usage;
    sci.format = format;
    sci.sampleCount = 1;
    sci.width = uint32_t(width);
    sci.height = uint32_t(height);
    sci.faceCount = 1;
    sci.arraySize = 1;
    sci.mipCount = 1;
    Swapchain s;
    xrCheck(xrCreateSwapchain(session, &sci, &s.handle), "xrCreateSwapchain");
    uint32_t n = 0;
    xrCheck(xrEnumerateSwapchainImages(s.handle, 0, &n, nullptr), "xrEnumerateSwapchainImages");
    s.images.assign(n, {XR_TYPE_SWAPCHAIN_IMAGE_VULKAN2_KHR});
    xrCheck(xrEnumerateSwapchainImages(s.handle, n, &n, reinterpret_cast<XrSwapchainImageBaseHeader*>(s.images.data())),
            "xrEnumerateSwapchainImages");
    return s;
  }

  // Acquires and waits for a swapchain image; a runtime that never releases one is an error.
  VkImage acquire(Swapchain& s) {
    uint32_t index = 0;
    xrCheck(xrAcquireSwapchainImage(s.handle, nullptr, &index), "xrAcquireSwapchainImage");
    XrSwapchainImageWaitInfo wait{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
    wait.timeout = 1'000'000'000;  // 1 s, five times
    for (int attempt = 0;; ++attempt) {
      XrResult r = xrWaitSwapchainImage(s.handle, &wait);
      if (r == XR_SUCCESS) break;
      if (r == XR_TIMEOUT_EXPIRED && attempt < 4) continue;
      if (r == XR_TIMEOUT_EXPIRED) throw Error("OpenXR: the runtime did not release a swapchain image within 5 s");
      xrCheck(r, "xrWaitSwapchainImage");
    }
    return s.images[index].image;
  }

  void release(Swapchain& s) {
    XrSwapchainImageReleaseInfo info{XR_TYPE_SWAPCHAIN_IMAGE_RELEASE_INFO};
    xrCheck(xrReleaseSwapchainImage(s.handle, &info), "xrReleaseSwapchainImage");
  }

  XrPath path(const char* text) const {
    XrPath p = XR_NULL_PATH;
    xrCheck(xrStringToPath(instance, text, &p), "xrStringToPath");
    return p;
  }

  XrAction makeAction(XrActionType type, const char* name, const char* localized) {
    XrActionCreateInfo aci{XR_TYPE_ACTION_CREATE_INFO};
    aci.actionType = type;
    std::strncpy(aci.actionName, name, XR_MAX_ACTION_NAME_SIZE - 1);
    std::strncpy(aci.localizedActionName, localized, XR_MAX_LOCALIZED_ACTION_NAME_SIZE - 1);
    XrAction action = XR_NULL_HANDLE;
    xrCheck(xrCreateAction(inputSet, &aci, &action), "xrCreateAction");
    return action;
  }

  // The action set: the gaze pose where there is an eye tracker, the buttons unless turned off.
  // A runtime that takes no controller binding leaves the levels to the keys (with a warning).
  void setUpInput(XrSessionInfo& info) {
    if (!info.eyeTracker && !options.controllerLevels) return;
    XrActionSetCreateInfo asci{XR_TYPE_ACTION_SET_CREATE_INFO};
    std::strcpy(asci.actionSetName, "photonvr");
    std::strcpy(asci.localizedActionSetName, "photonvr");
    xrCheck(xrCreateActionSet(instance, &asci, &inputSet), "xrCreateActionSet");
    auto suggest = [&](const char* profile, const std::vector<XrActionSuggestedBinding>& suggested) {
      XrInteractionProfileSuggestedBinding bindings{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
      bindings.interactionProfile = path(profile);
      bindings.countSuggestedBindings = uint32_t(suggested.size());
      bindings.suggestedBindings = suggested.data();
      return xrSuggestInteractionProfileBindings(instance, &bindings);
    };
    if (info.eyeTracker) {
      gazeAction = makeAction(XR_ACTION_TYPE_POSE_INPUT, "eye_gaze", "eye gaze");
      xrCheck(suggest("/interaction_profiles/ext/eye_gaze_interaction", {{gazeAction, path("/user/eyes_ext/input/gaze_ext/pose")}}),
              "xrSuggestInteractionProfileBindings (eye gaze)");
    }
    if (options.controllerLevels) {
      buttons[0] = {makeAction(XR_ACTION_TYPE_BOOLEAN_INPUT, "next_effect_level", "next effect level"), 'e', "next level"};
      buttons[1] = {makeAction(XR_ACTION_TYPE_BOOLEAN_INPUT, "scene_effect_levels", "the scene's effect levels"), '0',
                    "the scene's levels"};
      for (const ControllerBinding& b : kControllerBindings)
        if (XR_SUCCEEDED(suggest(b.profile, {{buttons[0].action, path(b.nextLevel)}, {buttons[1].action, path(b.sceneLevels)}})))
          ++info.controllerProfiles;
      if (info.controllerProfiles == 0)
        std::fprintf(stderr, "photonvr: warning: the OpenXR runtime took no controller bindings: effect levels from the keys only\n");
    }
    XrSessionActionSetsAttachInfo attach{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
    attach.countActionSets = 1;
    attach.actionSets = &inputSet;
    xrCheck(xrAttachSessionActionSets(session, &attach), "xrAttachSessionActionSets");
    if (gazeAction) {
      XrActionSpaceCreateInfo spaceInfo{XR_TYPE_ACTION_SPACE_CREATE_INFO};
      spaceInfo.action = gazeAction;
      spaceInfo.poseInActionSpace.orientation.w = 1.0f;
      xrCheck(xrCreateActionSpace(session, &spaceInfo, &gazeSpace), "xrCreateActionSpace");
    }
  }

  // After a sync: each button that went down since the last one is queued as a press.
  void readButtons() {
    for (const Button& b : buttons) {
      if (!b.action) continue;
      XrActionStateGetInfo get{XR_TYPE_ACTION_STATE_GET_INFO};
      get.action = b.action;
      XrActionStateBoolean state{XR_TYPE_ACTION_STATE_BOOLEAN};
      if (xrGetActionStateBoolean(session, &get, &state) == XR_SUCCESS && state.isActive && state.changedSinceLastSync &&
          state.currentState)
        presses.push_back(b);
    }
  }

  std::optional<LoopClock::time_point> toSteady(XrTime time) const {
    if (!toTimespec) return std::nullopt;
    timespec ts{};
    if (XR_FAILED(toTimespec(instance, time, &ts))) return std::nullopt;
    auto since = std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec);
    return LoopClock::time_point(std::chrono::duration_cast<LoopClock::duration>(since));
  }
};

XrPresenter::XrPresenter(const XrPresenterOptions& options) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.options = options;
  // The loader logs every failure to stderr on its own; photonvr reports the cause in one line.
  // XR_LOADER_DEBUG=error (or all) brings the loader's log back.
  setenv("XR_LOADER_DEBUG", "none", 0);
  uint32_t count = 0;
  XrResult r = xrEnumerateInstanceExtensionProperties(nullptr, 0, &count, nullptr);
  if (XR_FAILED(r))
    throw Error(std::string("no OpenXR runtime (") + xrResultName(r) +
                "): start one (SteamVR, Monado, Meta's) or point XR_RUNTIME_JSON at a runtime's manifest (XR_LOADER_DEBUG=error shows the loader's log)");
  std::vector<XrExtensionProperties> available(count, {XR_TYPE_EXTENSION_PROPERTIES});
  xrCheck(xrEnumerateInstanceExtensionProperties(nullptr, count, &count, available.data()), "xrEnumerateInstanceExtensionProperties");
  if (!hasExtension(available, XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME))
    throw Error("the OpenXR runtime does not offer XR_KHR_vulkan_enable2, the graphics binding photonvr uses");
  std::vector<const char*> extensions = {XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME};
  const bool haveDepth = options.depthLayer && hasExtension(available, XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME);
  const bool haveGaze = options.eyeGaze && hasExtension(available, XR_EXT_EYE_GAZE_INTERACTION_EXTENSION_NAME);
  const bool haveTimespec = hasExtension(available, XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME);
  if (haveDepth) extensions.push_back(XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME);
  if (haveGaze) extensions.push_back(XR_EXT_EYE_GAZE_INTERACTION_EXTENSION_NAME);
  if (haveTimespec) extensions.push_back(XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME);

  XrInstanceCreateInfo ici{XR_TYPE_INSTANCE_CREATE_INFO};
  std::strcpy(ici.applicationInfo.applicationName, "photonvr");
  ici.applicationInfo.applicationVersion = 1;
  std::strcpy(ici.applicationInfo.engineName, "photonvr");
  ici.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
  ici.enabledExtensionCount = uint32_t(extensions.size());
  ici.enabledExtensionNames = extensions.data();
  r = xrCreateInstance(&ici, &m.instance);
  if (r == XR_ERROR_RUNTIME_UNAVAILABLE || r == XR_ERROR_RUNTIME_FAILURE)
    throw Error(std::string("the OpenXR runtime failed to start (") + xrResultName(r) + ")");
  xrCheck(r, "xrCreateInstance");
  XrInstanceProperties ip{XR_TYPE_INSTANCE_PROPERTIES};
  xrCheck(xrGetInstanceProperties(m.instance, &ip), "xrGetInstanceProperties");
  info_.runtime = std::string(ip.runtimeName) + " " + std::to_string(XR_VERSION_MAJOR(ip.runtimeVersion)) + "." +
                  std::to_string(XR_VERSION_MINOR(ip.runtimeVersion)) + "." + std::to_string(XR_VERSION_PATCH(ip.runtimeVersion));
  if (haveTimespec) m.toTimespec = instanceProc<PFN_xrConvertTimeToTimespecTimeKHR>(m.instance, "xrConvertTimeToTimespecTimeKHR");
  info_.displayTimeKnown = m.toTimespec != nullptr;

  XrSystemGetInfo sgi{XR_TYPE_SYSTEM_GET_INFO};
  sgi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  r = xrGetSystem(m.instance, &sgi, &m.system);
  if (r == XR_ERROR_FORM_FACTOR_UNAVAILABLE) throw Error("the OpenXR runtime reports no headset connected (XR_ERROR_FORM_FACTOR_UNAVAILABLE)");
  xrCheck(r, "xrGetSystem");
  XrSystemEyeGazeInteractionPropertiesEXT gazeProps{XR_TYPE_SYSTEM_EYE_GAZE_INTERACTION_PROPERTIES_EXT};
  XrSystemProperties sp{XR_TYPE_SYSTEM_PROPERTIES};
  if (haveGaze) sp.next = &gazeProps;
  xrCheck(xrGetSystemProperties(m.instance, m.system, &sp), "xrGetSystemProperties");
  info_.system = sp.systemName;
  info_.eyeTracker = haveGaze && gazeProps.supportsEyeGazeInteraction;

  uint32_t viewCount = 0;
  xrCheck(xrEnumerateViewConfigurationViews(m.instance, m.system, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0, &viewCount, nullptr),
          "xrEnumerateViewConfigurationViews (the headset has no stereo view configuration?)");
  if (viewCount != 2) throw Error("the headset's stereo view configuration has " + std::to_string(viewCount) + " views, not 2");
  XrViewConfigurationView configViews[2] = {{XR_TYPE_VIEW_CONFIGURATION_VIEW}, {XR_TYPE_VIEW_CONFIGURATION_VIEW}};
  xrCheck(xrEnumerateViewConfigurationViews(m.instance, m.system, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 2, &viewCount, configViews),
          "xrEnumerateViewConfigurationViews");
  info_.recommendedWidth = int(configViews[0].recommendedImageRectWidth);
  info_.recommendedHeight = int(configViews[0].recommendedImageRectHeight);
  info_.maxWidth = int(configViews[0].maxImageRectWidth);
  info_.maxHeight = int(configViews[0].maxImageRectHeight);
  m.width = options.eyeWidth > 0 ? options.eyeWidth : info_.recommendedWidth;
  m.height = options.eyeHeight > 0 ? options.eyeHeight : info_.recommendedHeight;
  if (m.width > info_.maxWidth || m.height > info_.maxHeight)
    std::fprintf(stderr, "photonvr: warning: %dx%d per eye is beyond the runtime's stated maximum %dx%d\n", m.width,
                 m.height, info_.maxWidth, info_.maxHeight);
  info_.eyeWidth = m.width, info_.eyeHeight = m.height;
  uint32_t blendCount = 0;
  xrCheck(xrEnumerateEnvironmentBlendModes(m.instance, m.system, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0, &blendCount, nullptr),
          "xrEnumerateEnvironmentBlendModes");
  std::vector<XrEnvironmentBlendMode> blends(blendCount);
  xrCheck(xrEnumerateEnvironmentBlendModes(m.instance, m.system, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, blendCount, &blendCount, blends.data()),
          "xrEnumerateEnvironmentBlendModes");
  if (!blends.empty()) m.blend = blends[0];

  // Vulkan through the runtime: it adds the extensions its compositor needs and picks the GPU.
  auto requirementsFn = instanceProc<PFN_xrGetVulkanGraphicsRequirements2KHR>(m.instance, "xrGetVulkanGraphicsRequirements2KHR");
  auto createInstanceFn = instanceProc<PFN_xrCreateVulkanInstanceKHR>(m.instance, "xrCreateVulkanInstanceKHR");
  auto deviceFn = instanceProc<PFN_xrGetVulkanGraphicsDevice2KHR>(m.instance, "xrGetVulkanGraphicsDevice2KHR");
  auto createDeviceFn = instanceProc<PFN_xrCreateVulkanDeviceKHR>(m.instance, "xrCreateVulkanDeviceKHR");
  XrGraphicsRequirementsVulkan2KHR requirements{XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN2_KHR};
  xrCheck(requirementsFn(m.instance, m.system, &requirements), "xrGetVulkanGraphicsRequirements2KHR");
  VulkanContextOptions vo;
  vo.apiVersion = VK_API_VERSION_1_1;
  const XrVersion minimum = requirements.minApiVersionSupported;
  if (XR_MAKE_VERSION(1, 1, 0) < minimum) vo.apiVersion = VK_MAKE_API_VERSION(0, XR_VERSION_MAJOR(minimum), XR_VERSION_MINOR(minimum), 0);
  XrInstance xr = m.instance;
  XrSystemId system = m.system;
  vo.hooks.createInstance = [=](const VkInstanceCreateInfo& ci) {
    XrVulkanInstanceCreateInfoKHR info{XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR};
    info.systemId = system;
    info.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
    info.vulkanCreateInfo = &ci;
    VkInstance vk = VK_NULL_HANDLE;
    VkResult vr = VK_SUCCESS;
    XrResult xrr = createInstanceFn(xr, &info, &vk, &vr);
    if (XR_FAILED(xrr)) throw Error(std::string("the OpenXR runtime could not create a Vulkan instance (") + xrResultName(xrr) + ")");
    if (vr != VK_SUCCESS) throw Error(std::string("no Vulkan driver for the headset (vkCreateInstance through OpenXR: ") + vkResultName(vr) + ")");
    return vk;
  };
  vo.hooks.pickPhysicalDevice = [=](VkInstance vk) {
    XrVulkanGraphicsDeviceGetInfoKHR info{XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR};
    info.systemId = system;
    info.vulkanInstance = vk;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    XrResult xrr = deviceFn(xr, &info, &physical);
    if (XR_FAILED(xrr) || !physical)
      throw Error(std::string("the OpenXR runtime found no Vulkan device for the headset (") + xrResultName(xrr) + ")");
    return physical;
  };
  vo.hooks.createDevice = [=](VkPhysicalDevice physical, const VkDeviceCreateInfo& ci) {
    XrVulkanDeviceCreateInfoKHR info{XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR};
    info.systemId = system;
    info.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
    info.vulkanPhysicalDevice = physical;
    info.vulkanCreateInfo = &ci;
    VkDevice device = VK_NULL_HANDLE;
    VkResult vr = VK_SUCCESS;
    XrResult xrr = createDeviceFn(xr, &info, &device, &vr);
    if (XR_FAILED(xrr)) throw Error(std::string("the OpenXR runtime could not create the Vulkan device (") + xrResultName(xrr) + ")");
    if (vr != VK_SUCCESS) throw Error(std::string("vkCreateDevice through OpenXR failed (") + vkResultName(vr) + ")");
    return device;
  };
  m.vulkan = std::make_unique<VulkanContext>(vo);
  info_.vulkanDevice = m.vulkan->deviceName();

  XrGraphicsBindingVulkan2KHR binding{XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR};
  binding.instance = m.vulkan->instance();
  binding.physicalDevice = m.vulkan->physicalDevice();
  binding.device = m.vulkan->device();
  binding.queueFamilyIndex = m.vulkan->queueFamily();
  binding.queueIndex = 0;
  XrSessionCreateInfo sci{XR_TYPE_SESSION_CREATE_INFO};
  sci.next = &binding;
  sci.systemId = m.system;
  r = xrCreateSession(m.instance, &sci, &m.session);
  if (r == XR_ERROR_GRAPHICS_DEVICE_INVALID || r == XR_ERROR_GRAPHICS_REQUIREMENTS_CALL_MISSING || r == XR_ERROR_VALIDATION_FAILURE)
    throw Error(std::string("the OpenXR runtime refused the Vulkan graphics binding (") + xrResultName(r) + ")");
  xrCheck(r, "xrCreateSession");

  XrReferenceSpaceCreateInfo rsci{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  rsci.referenceSpaceType = options.stageSpace ? XR_REFERENCE_SPACE_TYPE_STAGE : XR_REFERENCE_SPACE_TYPE_LOCAL;
  rsci.poseInReferenceSpace.orientation.w = 1.0f;
  xrCheck(xrCreateReferenceSpace(m.session, &rsci, &m.space), options.stageSpace ? "xrCreateReferenceSpace (STAGE)" : "xrCreateReferenceSpace (LOCAL)");
  info_.space = options.stageSpace ? "STAGE" : "LOCAL";

  // Colour: the first format photonvr writes, in its order of preference (sRGB first).
  uint32_t formatCount = 0;
  xrCheck(xrEnumerateSwapchainFormats(m.session, 0, &formatCount, nullptr), "xrEnumerateSwapchainFormats");
  std::vector<int64_t> formats(formatCount);
  xrCheck(xrEnumerateSwapchainFormats(m.session, formatCount, &formatCount, formats.data()), "xrEnumerateSwapchainFormats");
  const int64_t preferred[] = {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_B8G8R8A8_SRGB, VK_FORMAT_R16G16B16A16_SFLOAT,
                               VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_B8G8R8A8_UNORM};
  int64_t colourFormat = 0;
  for (int64_t f : preferred)
    if (!colourFormat && std::find(formats.begin(), formats.end(), f) != formats.end()) colourFormat = f;
  if (!colourFormat) {
    std::string offered;
    for (int64_t f : formats) offered += (offered.empty() ? "" : ", ") + std::string(formatName(f) ? formatName(f) : std::to_string(f).c_str());
    throw Error("the OpenXR runtime offers no colour swapchain format photonvr can write (offered: " + offered +
                "; photonvr writes R8G8B8A8/B8G8R8A8 SRGB or UNORM, R16G16B16A16_SFLOAT)");
  }
  info_.colourFormat = formatName(colourFormat);
  DisplayEncoding encoding = DisplayEncoding::Rgba8Srgb;
  encodingOfFormat(VkFormat(colourFormat), encoding);
  for (int e = 0; e < 2; ++e)
    m.colour[e] = m.makeSwapchain(colourFormat, XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT);
  m.depthLayer = haveDepth && std::find(formats.begin(), formats.end(), int64_t(VK_FORMAT_D32_SFLOAT)) != formats.end();
  if (m.depthLayer) {
    try {
      for (int e = 0; e < 2; ++e)
        m.depth[e] = m.makeSwapchain(VK_FORMAT_D32_SFLOAT, XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT);
    } catch (const Error& e) {  // a runtime may not let depth be a copy target: go on without the layer
      std::fprintf(stderr, "photonvr: warning: no depth layer (%s)\n", e.what());
      for (Swapchain& s : m.depth)
        if (s.handle) xrDestroySwapchain(s.handle), s = {};
      m.depthLayer = false;
    }
  }
  info_.depthLayer = m.depthLayer;

  // The hand-over: from CUDA's memory when the runtime's GPU is the CUDA GPU, else via the host.
  HandOverPath path = HandOverPath::HostStaging;
  if (options.gpuImages) {
#ifdef PVR_HAVE_CUDA
    uint8_t uuid[16];
    if (cuda::currentDeviceUuid(uuid) && std::memcmp(uuid, m.vulkan->deviceUuid(), 16) == 0 && m.vulkan->canShareWithCuda())
      path = HandOverPath::CudaShared;
    else
      std::fprintf(stderr, "photonvr: warning: the headset's GPU (%s) is not the CUDA GPU or cannot share memory: images go through the host\n",
                   m.vulkan->deviceName().c_str());
#endif
  }
  EyeTransferOptions to;
  to.width = m.width, to.height = m.height;
  to.encoding = encoding;
  to.depth = m.depthLayer;
  to.nearZ = options.nearZ;
  to.exposure = options.exposure;
  to.path = path;
  to.colourViaImage = options.colourViaImage;
  m.transfer = std::make_unique<EyeTransfer>(*m.vulkan, to);
  info_.handOver = m.transfer->describe();

  m.setUpInput(info_);
  m.waitingSince = LoopClock::now();
}

XrPresenter::~XrPresenter() = default;

std::string XrPresenter::name() const { return "openxr (" + info_.runtime + ")"; }

FrameOutput XrPresenter::output(const Renderer& renderer) const {
  return impl_->transfer->options().path == HandOverPath::CudaShared ? FrameOutput::DeviceBuffers : FrameOutput::HostImages;
}

int XrPresenter::gazeFramesTracked() const { return impl_->gazeFramesTracked; }

int XrPresenter::controllerPresses() const { return impl_->controllerPresses; }

void XrPresenter::adjustOptions(RenderOptions& options) {
  Impl& m = *impl_;
  if (m.presses.empty()) return;
  const Button press = m.presses.front();
  m.presses.pop_front();
  ++m.controllerPresses;
  std::printf("xr: frame %llu: controller (%s): %s\n", (unsigned long long)(m.frames - 1), press.name,
              applyLoopKey(press.key, options).c_str());
  std::fflush(stdout);
}

void XrPresenter::requestStop() {
  Impl& m = *impl_;
  m.stopRequestedAt = LoopClock::now();
  if (lifecycle_.requestStop() == SessionCommand::RequestExit) xrCheck(xrRequestExitSession(m.session), "xrRequestExitSession");
}

bool XrPresenter::waitFrame(FrameRequest& request) {
  Impl& m = *impl_;
  for (;;) {
    XrEventDataBuffer event{XR_TYPE_EVENT_DATA_BUFFER};
    XrResult r;
    while ((r = xrPollEvent(m.instance, &event)) == XR_SUCCESS) {
      SessionCommand command = SessionCommand::None;
      if (event.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED) {
        auto& changed = reinterpret_cast<const XrEventDataSessionStateChanged&>(event);
        command = lifecycle_.onStateChanged(changed.state);
      } else if (event.type == XR_TYPE_EVENT_DATA_INSTANCE_LOSS_PENDING) {
        command = lifecycle_.onInstanceLossPending();
      }
      if (command == SessionCommand::BeginSession) {
        XrSessionBeginInfo begin{XR_TYPE_SESSION_BEGIN_INFO};
        begin.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
        xrCheck(xrBeginSession(m.session, &begin), "xrBeginSession");
      } else if (command == SessionCommand::EndSession) {
        m.transfer->waitIdle();
        xrCheck(xrEndSession(m.session), "xrEndSession");
      }
      event = {XR_TYPE_EVENT_DATA_BUFFER};
    }
    xrCheck(r, "xrPollEvent");
    if (lifecycle_.finished()) {
      if (lifecycle_.lost() && !lifecycle_.stopRequested())
        throw Error("the OpenXR session was lost (the runtime or the headset went away)");
      return false;
    }
    if (lifecycle_.stopRequested() &&
        std::chrono::duration<double>(LoopClock::now() - m.stopRequestedAt).count() > m.options.stopTimeoutSeconds)
      throw Error("the OpenXR runtime did not end the session within " + std::to_string(int(m.options.stopTimeoutSeconds)) + " s of the exit request");
    if (!lifecycle_.running()) {
      if (m.options.stop && m.options.stop->load() && !lifecycle_.stopRequested()) {
        requestStop();  // e.g. Ctrl-C while the runtime holds the session stopped (headset off)
        continue;
      }
      if (lifecycle_.sessionsBegun() == 0 &&
          std::chrono::duration<double>(LoopClock::now() - m.waitingSince).count() > m.options.readyTimeoutSeconds)
        throw Error("the OpenXR session did not become ready within " + std::to_string(int(m.options.readyTimeoutSeconds)) +
                    " s (is the headset on and the runtime's compositor running?)");
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      continue;
    }
    break;
  }
  m.frameState = {XR_TYPE_FRAME_STATE};
  XrResult r = xrWaitFrame(m.session, nullptr, &m.frameState);
  if (r == XR_ERROR_SESSION_LOST) throw Error("the OpenXR session was lost (XR_ERROR_SESSION_LOST)");
  xrCheck(r, "xrWaitFrame");
  r = xrBeginFrame(m.session, nullptr);
  if (r == XR_ERROR_SESSION_LOST) throw Error("the OpenXR session was lost (XR_ERROR_SESSION_LOST)");
  xrCheck(r, "xrBeginFrame");
  m.frameBegun = true;

  XrViewLocateInfo locate{XR_TYPE_VIEW_LOCATE_INFO};
  locate.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  locate.displayTime = m.frameState.predictedDisplayTime;
  locate.space = m.space;
  XrViewState viewState{XR_TYPE_VIEW_STATE};
  uint32_t count = 2;
  m.views[0] = m.views[1] = {XR_TYPE_VIEW};
  xrCheck(xrLocateViews(m.session, &locate, &viewState, 2, &count, m.views), "xrLocateViews");
  m.viewsValid = (viewState.viewStateFlags & XR_VIEW_STATE_ORIENTATION_VALID_BIT) &&
                 (viewState.viewStateFlags & XR_VIEW_STATE_POSITION_VALID_BIT);
  request.shouldRender = m.frameState.shouldRender && m.viewsValid;
  if (m.viewsValid) request.rig = rigFromViews(m.views, m.options.sceneFromSpace, m.width, m.height);
  request.rig.width = m.width, request.rig.height = m.height;
  copyGaze(m.options, request);
  request.gazeTracked = false;
  ++m.frames;
  XrResult synced = XR_SESSION_NOT_FOCUSED;
  if (m.inputSet && lifecycle_.focused()) {  // input reaches only the focused session
    XrActiveActionSet active{m.inputSet, XR_NULL_PATH};
    XrActionsSyncInfo sync{XR_TYPE_ACTIONS_SYNC_INFO};
    sync.countActiveActionSets = 1;
    sync.activeActionSets = &active;
    synced = xrSyncActions(m.session, &sync);
    // A button already down when focus comes (back) is not a press: it went down elsewhere (a
    // system menu, another application).
    if (synced == XR_SUCCESS && m.syncedFocused) m.readButtons();
  }
  m.syncedFocused = synced == XR_SUCCESS;
  if (m.gazeSpace && synced == XR_SUCCESS && m.viewsValid) {
    XrSpaceLocation location{XR_TYPE_SPACE_LOCATION};
    if (xrLocateSpace(m.gazeSpace, m.space, m.frameState.predictedDisplayTime, &location) == XR_SUCCESS &&
        (location.locationFlags & XR_SPACE_LOCATION_ORIENTATION_VALID_BIT)) {
      Pose gaze = composePoses(m.options.sceneFromSpace, poseFromXr(location.pose));
      float px = 0, py = 0;
      EyeCamera left = request.rig.eye(Eye::Left);
      if (left.projectDirection(gaze.toWorldDir({0, 0, -1}), px, py)) {
        request.gaze[0][0] = std::clamp(px / float(m.width), 0.0f, 1.0f);
        request.gaze[0][1] = std::clamp(py / float(m.height), 0.0f, 1.0f);
        request.verge = true;  // the right eye fixates what the left eye's gaze meets
        request.gazeTracked = true;
        ++m.gazeFramesTracked;
      }
    }
  }
  request.deadline = m.toSteady(m.frameState.predictedDisplayTime);
  if (m.frameState.predictedDisplayPeriod > 0) request.displayPeriodMs = double(m.frameState.predictedDisplayPeriod) * 1e-6;
  return true;
}

void XrPresenter::present(const PresentedFrame& frame) {
  Impl& m = *impl_;
  if (!m.frameBegun) return;
  m.frameBegun = false;
  XrCompositionLayerProjectionView views[2] = {{XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW}, {XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW}};
  XrCompositionLayerDepthInfoKHR depth[2] = {{XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR}, {XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR}};
  XrCompositionLayerProjection layer{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
  const XrCompositionLayerBaseHeader* layers[1] = {reinterpret_cast<const XrCompositionLayerBaseHeader*>(&layer)};
  const bool submit = frame.result && m.frameState.shouldRender && m.viewsValid;
  if (submit) {
    EyeSource sources[2];
    EyeTarget targets[2];
    for (int e = 0; e < 2; ++e) {
      sources[e] = eyeSourceOf(frame, Eye(e));
      targets[e].colour = m.acquire(m.colour[e]);
      targets[e].colourLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
      if (m.depthLayer) {
        targets[e].depth = m.acquire(m.depth[e]);
        targets[e].depthLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
      }
    }
    m.transfer->handOver(sources, targets);
    for (int e = 0; e < 2; ++e) {
      m.release(m.colour[e]);
      if (m.depthLayer) m.release(m.depth[e]);
      views[e].pose = m.views[e].pose;  // the poses the eyes were rendered with
      views[e].fov = m.views[e].fov;
      views[e].subImage.swapchain = m.colour[e].handle;
      views[e].subImage.imageRect = {{0, 0}, {m.width, m.height}};
      if (m.depthLayer) {
        depth[e].subImage.swapchain = m.depth[e].handle;
        depth[e].subImage.imageRect = {{0, 0}, {m.width, m.height}};
        depth[e].minDepth = 0.0f;
        depth[e].maxDepth = 1.0f;
        depth[e].nearZ = INFINITY;  // depth 0: infinitely far (reversed Z)
        depth[e].farZ = m.options.nearZ;
        views[e].next = &depth[e];
      }
    }
    layer.space = m.space;
    layer.viewCount = 2;
    layer.views = views;
  }
  XrFrameEndInfo end{XR_TYPE_FRAME_END_INFO};
  end.displayTime = m.frameState.predictedDisplayTime;
  end.environmentBlendMode = m.blend;
  end.layerCount = submit ? 1 : 0;
  end.layers = submit ? layers : nullptr;
  XrResult r = xrEndFrame(m.session, &end);
  if (r == XR_ERROR_SESSION_LOST) throw Error("the OpenXR session was lost (XR_ERROR_SESSION_LOST)");
  xrCheck(r, "xrEndFrame");
}

}  // namespace pvr
