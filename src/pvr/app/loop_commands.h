#pragma once
// The commands that run the frame loop: `xr` (an OpenXR headset, or --offscreen without one) and
// `view` (the desktop viewer). The command line has made the scene, rig and options already.
#include <string>
#include <vector>

#include <memory>
#include <optional>

#include "pvr/app/trajectory.h"
#include "pvr/control/budget_controller.h"
#include "pvr/foveation/mask.h"
#include "pvr/render/renderer.h"
#include "pvr/scene/scene.h"

namespace pvr {

struct LoopCommandArgs {
  uint64_t frames = 0;           ///< 0: until the session / window ends (xr: Ctrl-C)
  uint64_t warmup = 0;
  std::string stats = "out/xr_stats.json";
  bool offscreen = false;        ///< xr: no runtime; views from --trajectory or the scene's head
  std::string handOver = "vulkan";  ///< offscreen: vulkan (into Vulkan images, timed) | none
  double refreshHz = 90.0;       ///< offscreen display slot
  std::string cudaCopy = "buffer";  ///< CUDA hand-over: buffer (buffer-to-image copy) | image (image-to-image)
  bool paced = false;            ///< offscreen: wait for each slot as vsync would
  bool stage = false;            ///< xr: STAGE reference space
  bool depthLayer = true;
  float nearZ = 0.05f;
  double readyTimeout = 10.0;
  bool eyeSizeGiven = false;     ///< xr: --eye-size overrides the runtime's recommended size
  bool stdinKeys = false;        ///< xr: read keys (pvr/loop/loop_keys.h) from standard input even when it is no terminal
  float exposure = 1.0f;
  // view
  std::string screenshot = "out/view";
  std::string keys;
  bool noPanel = false;
  std::string sceneName;         ///< as given, for the settings file
  std::string acuity = "linear";
  std::string budget;             ///< --budget-ms: milliseconds or "display"; empty: no controller
  std::string controllerProfile;  ///< empty: ControlProfile::generic
};

// Writes `j` (indented) to `path`, making its folder; throws pvr::Error if it cannot.
void writeJson(const std::string& path, const nlohmann::json& j);

// --budget-ms: a number of milliseconds, or "display" for the display's frame period (the OpenXR
// runtime's predicted period, the monitor's refresh, xr --offscreen's slot), followed as it changes.
struct BudgetSpec {
  double ms = 0;                ///< 0: no controller
  bool followsDisplay = false;  ///< ms is then 1000/90 until the presenter reports its period
  bool enabled() const { return ms > 0; }
};
// Empty: no controller. Throws pvr::Error (one line) for anything else that is not a budget.
BudgetSpec parseBudget(const std::string& text);

// The controller for a scene's effect groups, from the options the user asked for and the final
// rig; its foveation knob uses the options' mask, or one made for the rig into `mask`. Null when
// the budget is not enabled. Throws pvr::Error for a bad profile.
std::unique_ptr<BudgetController> makeBudgetController(const BudgetSpec& budget, const std::string& profilePath, const Scene& scene,
                                                       const RenderOptions& options, const StereoRig& rig,
                                                       const std::string& acuity, std::optional<FoveationMask>& mask);

struct LoopSetup {
  BackendKind backend = BackendKind::Auto;
  const Scene* scene = nullptr;
  StereoRig rig;
  RenderOptions options;         ///< foveation.mask points at a mask the caller keeps
  std::vector<TrajectoryFrame> trajectory;
  std::string photons, radius;   ///< as given (for the log)
};

int runXrCommand(const LoopCommandArgs& args, const LoopSetup& setup);
int runViewCommand(const LoopCommandArgs& args, const LoopSetup& setup);

}  // namespace pvr
