#pragma once
// photonvr on the desktop: a GLFW window on the Vulkan layer showing both eyes side by side (or
// one), mouse-look and WASD moving the head, the cursor setting the gaze, and a Dear ImGui panel
// with every rendering option live and the stage timings as rolling plots. F12 writes what each
// eye shows as PNG (the same bytes `render` writes for the same pose) and the settings as JSON
// that `render` and `xr` accept (--settings). Keys can be scripted (tests under Xvfb).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "pvr/loop/presenter.h"

namespace pvr {

// What the panel edits, in the command line's spellings (the settings file holds the same).
struct ViewerSettings {
  int photonsLog2 = 8;             ///< photons: 2^n x 2^n
  float radius = 0.05f;
  int map = 0;                     ///< 0 hashgrid, 1 kdtree
  int estimator = 0;               ///< 0 radius, 1 knn
  int k = 32;
  bool clippedBoundary = false;    ///< --boundary clipped: the estimate's disc clipped at walls and edges
  int kernel = 1;                  ///< single, hybrid, shared, sorted
  int stereo = 0;                  ///< separate, scatter, gather
  bool foveated = false;
  int acuity = 0;                  ///< 0 linear, 1 geisler-perry
  bool taa = false;
  float taaBlend = 0.1f;
  bool denoise = false;
  bool rasterPrimary = false;      ///< --primary raster (the G-buffer pre-pass)
  int effects = 0;                 ///< 0: each material's own level; 1 + EffectLevel: --effects for all
  float exposure = 1.0f;
  int backend = 0;                 ///< 0 cpu, 1 cuda
  bool bothEyes = true;
};

struct ScriptedKey {
  uint64_t frame = 0;  ///< pressed before this frame (0-based)
  int key = 0;         ///< GLFW key code
};
// "3:F12,5:Escape" -> keys; throws pvr::Error for an unknown key name or a malformed entry.
std::vector<ScriptedKey> parseKeyScript(const std::string& text);

struct ViewerOptions {
  int windowWidth = 0, windowHeight = 0;  ///< 0: both eyes at their size, plus the panel
  std::string screenshotPrefix = "out/view";
  std::vector<ScriptedKey> script;
  bool panel = true;
  float moveSpeed = 0.5f;         ///< scene units per second under WASD
  bool cudaAvailable = false;     ///< the panel offers the CUDA backend
  // Writes the settings file of the moment (the app knows the scene and the file format).
  std::function<void(const std::string& path, const ViewerSettings&, const FrameRequest&)> writeSettings;
};

class ViewerPresenter : public Presenter {
 public:
  // Opens the window (throws pvr::Error with one line: no display, no Vulkan device that can
  // present to it). `rig` gives the eye size, FOV and the starting head pose.
  ViewerPresenter(const StereoRig& rig, const ViewerSettings& settings, const ViewerOptions& options);
  ~ViewerPresenter() override;
  std::string name() const override { return "viewer"; }
  FrameOutput output(const Renderer& renderer) const override;
  bool waitFrame(FrameRequest& request) override;
  void present(const PresentedFrame& frame) override;
  void requestStop() override;
  void adjustOptions(RenderOptions& options) override;

  // The panel asked for another backend: the app makes a new renderer and runs the loop again.
  bool backendChangeRequested() const;
  void clearBackendChange();
  const ViewerSettings& settings() const;
  std::vector<std::string> screenshotsWritten() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pvr
