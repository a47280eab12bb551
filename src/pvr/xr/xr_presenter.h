#pragma once
// photonvr on a headset: the frame loop's presenter for any OpenXR runtime (SteamVR, Monado,
// Meta's), through the Khronos loader with the XR_KHR_vulkan_enable2 graphics binding. The
// runtime creates the Vulkan instance and device and picks the GPU; each eye has a swapchain;
// per frame xrWaitFrame -> xrLocateViews at the predicted display time -> the views become the
// rig -> render -> hand-over into the acquired swapchain images -> xrEndFrame with a projection
// layer (and a depth layer when the runtime offers XR_KHR_composition_layer_depth).
#include <atomic>
#include <memory>
#include <string>

#include "pvr/loop/presenter.h"
#include "pvr/xr/session_lifecycle.h"

namespace pvr {

struct XrPresenterOptions {
  int eyeWidth = 0, eyeHeight = 0;   ///< swapchain size per eye; 0: the runtime's recommended size
  bool depthLayer = true;            ///< submit depth when the runtime offers XR_KHR_composition_layer_depth
  float nearZ = 0.05f;               ///< metres of depth 1 in the depth layer (reversed Z, far at infinity)
  bool stageSpace = false;           ///< STAGE reference space (floor level) instead of LOCAL (head at start)
  Pose sceneFromSpace;               ///< where the reference space's origin sits in the scene
  bool eyeGaze = true;               ///< use XR_EXT_eye_gaze_interaction when the system has an eye tracker
  bool controllerLevels = true;      ///< controller buttons change the effect levels (as the keys e and 0)
  float gaze[2][2] = {{0.5f, 0.5f}, {0.5f, 0.5f}};  ///< otherwise this gaze (image fractions)
  bool verge = true;
  float exposure = 1.0f;
  bool gpuImages = false;            ///< the renderer is CUDA: hand over device buffers (no host copy)
  bool colourViaImage = false;       ///< CUDA hand-over through a shared image (else a shared buffer)
  double readyTimeoutSeconds = 10;   ///< the session must become READY within this
  double stopTimeoutSeconds = 5;     ///< after a stop request, the runtime must end the session within this
  const std::atomic<bool>* stop = nullptr;  ///< Ctrl-C: seen also while waiting for the runtime (a stopped session)
};

// What the presenter found and chose, for the log and the statistics.
struct XrSessionInfo {
  std::string runtime, system, colourFormat, handOver, space;
  int eyeWidth = 0, eyeHeight = 0, recommendedWidth = 0, recommendedHeight = 0, maxWidth = 0, maxHeight = 0;
  bool depthLayer = false, eyeTracker = false, displayTimeKnown = false;
  int controllerProfiles = 0;  ///< controller interaction profiles whose bindings the runtime took
  std::string vulkanDevice;
};

// The name of an XrResult ("XR_ERROR_RUNTIME_UNAVAILABLE").
const char* xrResultName(XrResult result);

class XrPresenter : public Presenter {
 public:
  // Connects to the runtime and sets up the session. Throws pvr::Error with one line naming the
  // cause: no runtime, no headset, no Vulkan device, a refused graphics binding, no usable
  // swapchain format.
  explicit XrPresenter(const XrPresenterOptions& options);
  ~XrPresenter() override;
  std::string name() const override;
  FrameOutput output(const Renderer& renderer) const override;
  bool waitFrame(FrameRequest& request) override;
  void present(const PresentedFrame& frame) override;
  void requestStop() override;
  // Applies one controller press seen since the last frame (one a frame, as the keys): the
  // right hand's select, A or trackpad puts every material at the next effect level, the left
  // hand's select or trackpad, or the right hand's B, gives each material its own level again.
  void adjustOptions(RenderOptions& options) override;

  const XrSessionInfo& info() const { return info_; }
  const SessionLifecycle& lifecycle() const { return lifecycle_; }
  int gazeFramesTracked() const;
  int controllerPresses() const;  ///< presses applied to the options

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  XrSessionInfo info_;
  SessionLifecycle lifecycle_;
};

}  // namespace pvr
