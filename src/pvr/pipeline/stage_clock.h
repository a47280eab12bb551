#pragma once
// The frame's stages, and the clock that times them: a host clock on the CPU, CUDA events on the
// GPU (read once the frame is finished, so timing never stalls the device). A stage may run
// several times in a frame (one eye-ray pass per sample); its time is the sum.
#include <array>
#include <chrono>

namespace pvr {

enum class Stage : int {
  PhotonTrace = 0,  ///< photons from the lights through the scene
  MapBuild,         ///< hash grid or kd-tree over the stored photons
  Scatter,          ///< the left eye's surfaces projected into the right image (stereo scatter)
  EyeRays,          ///< eye rays to their gather points (the whole shading for fused passes)
  Density,          ///< density estimation at the gather points
  Reconstruct,      ///< foveated: the image rebuilt from the mask's vertices
  Denoise,          ///< spatio-temporal denoising of the eye's image
  Temporal,         ///< TAA resolve against the eye's history
  Primary,          ///< the G-buffer pre-pass: both eyes' first hits rasterised (--primary raster)
  Count,
};

const char* stageName(Stage stage);  ///< "photon trace", "map build", ... (also the profiler's label)

// Stages of the whole frame are timed under kWholeFrame; per-eye stages under the eye (0, 1).
constexpr int kWholeFrame = -1;

class StageClock {
 public:
  virtual ~StageClock() = default;
  virtual void newFrame() = 0;  ///< forgets the last frame's times
  virtual void begin(Stage stage, int eye) = 0;
  virtual void end(Stage stage, int eye) = 0;
  // The stage's time in this frame, in ms; only once the backend has finished the frame.
  virtual double ms(Stage stage, int eye) = 0;
  // Adds a time measured elsewhere (another API's timestamps) to the stage's.
  virtual void add(Stage stage, int eye, double ms) = 0;
};

// Times one stage for the scope's life.
class StageScope {
 public:
  StageScope(StageClock& clock, Stage stage, int eye = kWholeFrame) : clock_(clock), stage_(stage), eye_(eye) {
    clock_.begin(stage_, eye_);
  }
  ~StageScope() { clock_.end(stage_, eye_); }
  StageScope(const StageScope&) = delete;
  StageScope& operator=(const StageScope&) = delete;

 private:
  StageClock& clock_;
  Stage stage_;
  int eye_;
};

// The host clock (steady_clock): right for backends whose stages finish before they return.
class HostStageClock : public StageClock {
 public:
  void newFrame() override { totals_.fill(0.0); }
  void begin(Stage stage, int eye) override { started_[slot(stage, eye)] = std::chrono::steady_clock::now(); }
  void end(Stage stage, int eye) override {
    const int s = slot(stage, eye);
    totals_[s] += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started_[s]).count();
  }
  double ms(Stage stage, int eye) override { return totals_[slot(stage, eye)]; }
  void add(Stage stage, int eye, double ms) override { totals_[slot(stage, eye)] += ms; }

 private:
  static int slot(Stage stage, int eye) { return int(stage) * 3 + eye + 1; }
  std::array<std::chrono::steady_clock::time_point, int(Stage::Count) * 3> started_{};
  std::array<double, int(Stage::Count) * 3> totals_{};
};

}  // namespace pvr
