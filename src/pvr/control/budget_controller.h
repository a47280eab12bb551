#pragma once
// The automatic controller that Ray-VR (section VI) names as future work: given a frame budget
// (11.1 ms at 90 Hz, or the display's period) it chooses, frame by frame, the photon count, the
// search radius, foveation, the denoiser and the effect level of each material group, so that the
// p99 frame time stays under the budget while the image loses the least quality.
//
// Cost model: every frame's measured stage times are divided by how that stage scales with the
// frame's setting (photon trace and map build ~ photons; density ~ photons x radius^2, the photons
// a query meets, x the share of the gather points at level gi x the shaded samples; eye rays ~ the
// groups' level costs x the shaded samples; denoising ~ a-trous passes, a pass over the photon map
// alone counted at photonMapPassShare; the rest is constant), which
// leaves unit costs that depend on the view only. A candidate's time is the largest unit costs of
// the last few frames times its scales: the view's cost is tracked as it changes, settings are
// compared on equal terms.
// Quality model: each knob's added error (relMSE against the converged reference) measured alone
// at a calibration view, summed (ControlProfile; `bench --suite effects --profile-out` makes one),
// but for the photon count and radius, whose steps are measured both with the best denoiser and
// without one, and mixed per denoise step: the denoiser hides most of their noise.
// It starts by probing the view for two frames at the fewest photons (the first frame's
// allocations are not counted), foveated where a mask is available, and a third at full
// resolution: the two give the foveated eye rays' time over the full-resolution ones' at this
// view, which replaces the profile's (a profile's ratio from another view, or a sample count, can
// be 4x off: a controller that believes full resolution costs 4x what it does never leaves the
// foveated pass; the third frame may run over the budget). Each later switch between the two
// measures it again. Then it takes the best setting that fits.
// Hysteresis: the setting is lowered at once, as far as needed, when the predicted time of the
// current one passes budget x (1 - margin); it is raised by at most two knob steps at a time (one
// up, or one up and one down), only after the headroom has held for `holdFrames` frames, at most
// `maxRaisesPerSecond`, and only for a gain above `minGain`: no oscillation, no popping. Once,
// when the first second's overruns replace the start-up margin, the raise searches every setting:
// the start-up's cautious choice can sit where no two steps lead to the best one that fits.
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pvr/pipeline/frame_options.h"
#include "pvr/pipeline/frame_result.h"

namespace pvr {

// The levels the controller chooses among (Path accumulates while the head is still: not a
// per-frame choice).
constexpr int kControlledLevels = 4;  // raster, shadows, reflections, gi

// One point of the controller's search space: an index into each of the profile's ladders.
struct ControlSetting {
  int photons = 0;      ///< ControlProfile::photonSides
  int radius = 0;       ///< ControlProfile::radiusScales
  int denoise = 0;      ///< ControlProfile::denoiseIterations and denoiseDirectIterations (0 iterations: off)
  bool foveated = false;
  std::array<uint8_t, kMaxEffectGroups> levels{};  ///< per effect group, an EffectLevel below Path
  bool operator==(const ControlSetting&) const = default;
};

// What the controller knows of a scene, calibrated offline (or the built-in generic model).
struct ControlProfile {
  std::string scene, device;  ///< what it was calibrated on (informative)
  std::vector<std::string> groups{"rest"};  ///< the scene's effect groups, group 0 first
  std::vector<uint32_t> photonSides{128, 181, 256, 362, 512, 724, 1024};  ///< emitted photons = side^2
  std::vector<float> radiusScales{0.7f, 1.0f, 1.4f};  ///< times the radius the options ask for
  // The denoiser's ladder: a-trous passes, and of them the direct signal's (its noise is finer than
  // the photon map's: fewer passes cost less at about the same error, docs/benchmarks.md).
  std::vector<int> denoiseIterations{0, 2, 4, 5, 5};
  std::vector<int> denoiseDirectIterations{0, 2, 2, 2, 5};
  // Quality: relMSE of the best setting, and what each knob's step adds to it (may be negative:
  // the denoiser lowers the error).
  double topError = 0.02;
  std::vector<double> photonError, radiusError, denoiseError;  ///< one per ladder step
  double foveatedError = 0.01;
  // The photon and radius steps' errors again with the denoiser off (empty: as with it). The
  // denoiser hides most of the photon map's noise, so without it fewer photons or a smaller radius
  // cost far more: on the H100's Sponza walk 512^2 photons undenoised gave relMSE 0.048 where the
  // denoised steps added up to 0.025. A denoise step takes the two ladders mixed by how much of the
  // measuring step's gain it gives up (undenoisedWeight). Relative to the best photon and radius
  // steps with the denoiser off (0 there), as fitErrors measures them.
  std::vector<double> photonErrorUndenoised, radiusErrorUndenoised;
  int laddersDenoiseStep = -1;  ///< the denoise step photonError and radiusError were measured at (-1: the least-error step)
  std::vector<std::array<double, kControlledLevels>> levelError;  ///< per group, per level (gi: 0)
  // Cost shapes: eye-ray time of each group's level relative to all at gi (whose eye rays are
  // 1), the share of the density work each group's gather points do, the foveated eye pass's time
  // over the full-resolution one's.
  std::vector<std::array<double, kControlledLevels>> levelRayCost;  ///< per group, per level: added to 1
  std::vector<double> densityShare;  ///< per group; the shares sum to 1
  double foveatedSamples = 0.25;
  // What the photon pass (trace + build) and the density stage cost whatever the photon count
  // (launches, the grid's clearing), as shares of their cost at the top count: each is affine in
  // the photons, not proportional (on the H200's Sponza 128^2 photons took 0.66 ms, 724^2 3.8 ms).
  double photonFixedShare = 0.1, densityFixedShare = 0.1;
  double denoiseMsPerIteration = 0.2;  ///< until a denoised frame has been measured
  // A pass over the photon-map signal alone, over a pass over both signals (ncu on the H100's
  // Sponza walk: 0.78).
  double photonMapPassShare = 0.78;
  // A denoise step's cost in passes over both signals (the denoise cost's scale).
  double denoisePasses(int step) const;
  int leastErrorDenoiseStep() const;  ///< the denoise step of least error (the best setting's)
  // The share of the undenoised photon and radius errors at a denoise step: 1 with the denoiser
  // off, 0 at the step the denoised ladders were measured at (laddersDenoiseStep), in between the
  // share of that step's gain over no denoiser that the step gives up. 0 wherever no undenoised
  // ladder is known.
  double undenoisedWeight(int step) const;
  // Sets the quality model from measurements: `errorOf(setting)` is the relMSE a setting gives
  // (at one view, or the mean over a walk's reference views). `top` (the best setting) and each
  // knob's step from it alone are measured; the terms are the differences, the denoiser's relative
  // to no denoiser, photon and level steps never below 0. Where the ladder has the denoiser off
  // and the top has it on, the photon and radius steps are measured once more without it, from
  // the top with the denoiser off. Costs are left as they are.
  void fitErrors(const ControlSetting& top, const std::function<double(const ControlSetting&)>& errorOf);

  // The generic model for a scene with these groups: variance ~ 1 / (photons x radius^2), bias ~
  // radius^2, each group's levels by its share, the foveated frame 4x cheaper.
  static ControlProfile generic(const std::vector<std::string>& groups);
  // A profile file (JSON, as toJson writes); throws pvr::Error naming the file and what is wrong,
  // including ladders out of range and groups the scene does not have.
  static ControlProfile load(const std::string& path, const std::vector<std::string>& sceneGroups);
  nlohmann::json toJson() const;
  void validate() const;  ///< throws pvr::Error: sizes, ranges, non-finite values
};

struct BudgetControllerParams {
  double budgetMs = 1000.0 / 90.0;
  // The frame loop sets the budget to the display's frame period (FrameRequest::displayPeriodMs)
  // whenever the presenter reports one (`--budget-ms display`).
  bool followsDisplay = false;
  // The predicted time must stay under budget x (1 - margin). The margin follows how far the
  // frames of the last second ran over their predictions (+ 2 %), within [margin, maxMargin];
  // startMargin until a second has been seen.
  double margin = 0.04, maxMargin = 0.25, startMargin = 0.12;
  double raiseHeadroom = 0.05;  ///< raising needs the new setting under budget x (1 - margin - this)
  int holdFrames = 10;          ///< frames of headroom before a raise
  double maxRaisesPerSecond = 4.0;
  double minGain = 0.03;        ///< a raise must lower the predicted error by this fraction
  int window = 6;               ///< frames whose unit costs the prediction takes the largest of
  bool foveationAvailable = false;  ///< a mask exists to switch to
};

// The controller's decision for one frame, for the stats.
struct ControlDecision {
  ControlSetting setting;
  double predictedMs = 0, predictedError = 0;
  double budgetMs = 0;  ///< the budget this decision kept to
  const char* change = "hold";  ///< "hold" | "lower" | "raise" | "replan" (over the limit, to a better setting that fits) | "start"
};

// Per-frame measured stage times, in the terms of the cost model.
struct ControlCosts {
  double photonMs = 0;   ///< photon trace + map build
  double densityMs = 0;  ///< both eyes
  double rayMs = 0;      ///< both eyes' eye rays
  double denoiseMs = 0;  ///< both eyes
  double restMs = 0;     ///< the frame's time minus the above
  static ControlCosts of(const StageTimings& t, double frameMs);
  double total() const { return photonMs + densityMs + rayMs + denoiseMs + restMs; }
};

class BudgetController {
 public:
  // `base`: the options the user asked for (radius, effect levels, denoiser parameters); the
  // controller starts from the best setting and writes each frame's into a copy of them.
  BudgetController(const ControlProfile& profile, const BudgetControllerParams& params, const RenderOptions& base,
                   const FoveationMask* mask);

  // Before a frame at time `nowMs` (any monotonic clock): the setting to render with.
  ControlDecision decide(double nowMs);
  // A new budget (the display's period changed): decisions from the next one on keep to it.
  // Periods outside (0, 10000] ms are ignored: a runtime may report 0 before it knows.
  void setBudget(double budgetMs);
  // New options from the user (the viewer's panel): what the knobs apply to from now on.
  void setBase(const RenderOptions& base) { base_ = base; }
  // The options of a setting (base with the setting's knobs applied).
  RenderOptions optionsFor(const ControlSetting& s) const;
  // After the frame rendered with the last decision: its measured costs.
  void observe(const ControlCosts& measured);

  // The models, for the tests and the logs.
  double predictMs(const ControlSetting& s) const;  ///< with the current window of unit costs
  double predictError(const ControlSetting& s) const;
  ControlCosts scaleOf(const ControlSetting& s) const;  ///< each cost term's scale at a setting
  const ControlSetting& best() const { return best_; }
  const ControlSetting& current() const { return current_; }
  const ControlProfile& profile() const { return profile_; }
  const BudgetControllerParams& params() const { return params_; }
  double currentMargin() const { return margin(); }
  // The foveated eye rays' time over the full-resolution ones', as last measured (the profile's
  // foveatedSamples until then).
  double foveatedRatio() const { return profile_.foveatedSamples; }

  static nlohmann::json toJson(const ControlSetting& s, const ControlProfile& profile);

 private:
  std::vector<ControlSetting> raisesOf(const ControlSetting& s) const;
  bool hasGi(const ControlSetting& s) const;

  ControlProfile profile_;
  BudgetControllerParams params_;
  RenderOptions base_;
  const FoveationMask* mask_;
  int groups_;
  ControlSetting best_, current_;
  std::vector<ControlSetting> all_;  ///< every setting, for lowering
  std::vector<ControlCosts> units_;  ///< the last frames' unit costs (ring, newest last)
  // The same frames' measured costs and settings (units_ is recomputed from them when the
  // foveated ratio is measured again).
  std::vector<std::pair<ControlCosts, ControlSetting>> measured_;
  void unitFrom(ControlCosts& unit, const ControlCosts& measured, const ControlSetting& s);
  void learnFoveatedRatio(double ratio);
  // The foveated pass's time over the full-resolution one's from a frame of each (0: unknown).
  double foveatedRatioOf(const ControlCosts& foveated, const ControlSetting& foveatedSetting, const ControlCosts& full,
                         const ControlSetting& fullSetting) const;
  double margin() const;  ///< the margin now (BudgetControllerParams::margin)
  std::vector<double> overruns_;   ///< the last second's measured / predicted - 1
  double lastPredictedMs_ = 0;
  double densityPerRay_ = -1;      ///< the unit density cost over the unit eye-ray cost, when last measured
  int headroomFrames_ = 0;
  double lastRaiseMs_ = -1e30;
  bool started_ = false, settled_ = false;
  bool replanned_ = false;  ///< the one search over every setting when the start-up margin gives way to the measured one
};

// Every controlled frame: the decision and what the frame then cost. Its JSON (the stats file's
// "controller") has the budget, the p99 and the frames over it, the changes, and one entry per
// frame; `errors` may add a measured error (against a reference) to chosen frames.
struct ControlLogEntry {
  ControlDecision decision;
  double frameMs = 0;
  ControlCosts costs;
  double measuredError = -1;  ///< < 0: not measured
};
class ControlLog {
 public:
  void add(const ControlDecision& d, double frameMs, const ControlCosts& costs) { entries_.push_back({d, frameMs, costs}); }
  std::vector<ControlLogEntry>& entries() { return entries_; }
  const std::vector<ControlLogEntry>& entries() const { return entries_; }
  size_t framesOver(double budgetMs) const;
  // Frames over the budget in force when each was decided (the display's period may change).
  size_t framesOverTheirBudget() const;
  bool budgetChanged() const;  ///< not every frame kept to the same budget
  size_t changes() const;  ///< frames whose decision changed the setting
  nlohmann::json toJson(const BudgetController& controller) const;
  std::string summary(const BudgetController& controller) const;  ///< one line

 private:
  std::vector<ControlLogEntry> entries_;
};

}  // namespace pvr
