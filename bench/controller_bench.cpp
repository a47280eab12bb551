#include "controller_bench.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "bench_util.h"
#include "pvr/app/options.h"
#include "pvr/app/trajectory.h"
#include "pvr/control/budget_controller.h"
#include "pvr/foveation/gaze.h"
#include "pvr/foveation/mask.h"
#include "pvr/image/image_compare.h"
#include "pvr/reference/progressive_reference.h"
#include "pvr/scene/scene.h"
#include "pvr/util/error.h"
#include "pvr/util/latency_stats.h"

namespace pvr {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// One walk at one policy (the controller, or a fixed setting).
struct Walk {
  std::string name;
  std::vector<double> ms;                   ///< per frame of the stride
  std::vector<int> frames;                  ///< the walk's frame of each
  std::vector<std::pair<int, double>> error;  ///< (frame, mean relMSE of the eyes) at sampled frames
  ControlLog log;                           ///< the controller's
  std::map<std::string, int> settingFrames;  ///< the controller's time in each setting
  double p99() const { return latencyStats(ms).p99; }
  double overFraction(double budget) const {
    return double(std::count_if(ms.begin(), ms.end(), [&](double m) { return m > budget; })) / double(std::max<size_t>(ms.size(), 1));
  }
  double meanError() const {
    double s = 0;
    for (const auto& e : error) s += e.second;
    return error.empty() ? 0.0 : s / double(error.size());
  }
};

struct SampledView {
  int frame;
  std::array<Image, 2> reference;
};

double frameError(const FrameResult& f, const SampledView& v) {
  return 0.5 * (relativeMse(f.eyes[0].image, v.reference[0]) + relativeMse(f.eyes[1].image, v.reference[1]));
}

// The first sampled view: half an interval in (on a frame the fixed walks render), so that no
// view falls on the controller's start-up probes.
size_t firstView(const FrameBenchArgs& args) {
  return size_t(args.errorEvery / 2 / args.fixedStride * args.fixedStride);
}

// Frames a strided walk renders one by one before each sampled view (a third of a second at
// 90 Hz): the view's frame then has the history of the denoiser and of TAA that a walk at every
// frame gives it, where every 9th frame alone would have reprojected across 9 frames of motion
// and shown a fixed setting's denoiser with a history it rejected.
constexpr size_t kHistoryFrames = 30;

// Renders the walk: `choose` gives each frame's options (and sees its measured time after).
// `stride` > 1: every stride-th frame, and the kHistoryFrames frames before each sampled view.
template <class Choose, class Observe>
Walk walk(FrameRenderer& renderer, StereoRig rig, const std::vector<TrajectoryFrame>& trajectory,
          const std::vector<SampledView>& views, Choose choose, Observe observe, int stride = 1) {
  Walk w;
  renderer.resetHistory();
  size_t nextView = 0;
  const auto start = Clock::now();
  for (size_t f = 0; f < trajectory.size(); ++f) {
    const bool beforeView = nextView < views.size() && f + kHistoryFrames >= size_t(views[nextView].frame);
    if (f % size_t(stride) != 0 && !beforeView) continue;
    rig.head = trajectory[f].head;
    RenderOptions o = choose(msSince(start));
    copyGaze(trajectory[f], o.foveation);
    const auto frameStart = Clock::now();
    FrameResult frame = renderer.render(rig, o, false);
    const double ms = msSince(frameStart);
    // Frame times of the stride's frames only (the windows before the views would weigh the
    // statistics towards a ninth of the walk); the views' frames are among them.
    if (f % size_t(stride) == 0) w.ms.push_back(ms), w.frames.push_back(int(f));
    observe(frame.timings, ms);
    if (nextView < views.size() && views[nextView].frame == int(f)) {
      // The shown image of this frame, read back outside the timed frame (a second render of the
      // same view: the temporal stages see it once more).
      const FrameResult shown = renderer.render(rig, o, true);
      w.error.push_back({int(f), frameError(shown, views[nextView])});
      ++nextView;
    }
  }
  return w;
}

std::string fmt2(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

}  // namespace

int runControllerBench(const FrameBenchArgs& args, BackendKind kind, nlohmann::json& json) {
  int failures = 0;
  if (args.walks.empty()) throw Error("--walks must name SCENE=TRAJECTORY pairs for the controller suite");
  if (args.referencePasses < 2 || args.referencePasses > kMaxReferencePasses)
    throw Error("--reference-passes must be between 2 and " + std::to_string(kMaxReferencePasses));
  if (args.errorEvery < 1) throw Error("--error-every must be at least 1");
  if (args.fixedStride < 1 || args.errorEvery % args.fixedStride != 0)
    throw Error("--fixed-stride must be at least 1 and divide --error-every");
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // each row as it is measured (a long suite may be cut short)
  std::vector<double> budgets;
  for (const std::string& b : splitList(args.budgets)) {
    char* end = nullptr;
    const double v = std::strtod(b.c_str(), &end);
    if (end == b.c_str() || *end != 0 || !std::isfinite(v)) throw Error("--budgets must be numbers of ms, got '" + b + "'");
    if (!(v > 0.0) || v > 10000.0) throw Error("--budgets must be positive milliseconds, got '" + b + "'");
    budgets.push_back(v);
  }
  std::printf("\nThe budget controller on walks through scenes: frame time (host wall time of the stereo frame, images "
              "left on the device) mean / p50 / p99 and frames over the budget; error: mean relMSE of both eyes against "
              "references (%d progressive passes of 1024x1024 photons) of every %dth frame's view from frame %zu; fixed settings render every %dth frame and "
              "the %zu before each of those views (their temporal history). Fixed settings: each "
              "setting the controller spent at least 3 %% of a walk in, and uniform ones.\n\n",
              args.referencePasses, args.errorEvery, firstView(args), args.fixedStride, kHistoryFrames);
  for (const std::string& item : splitList(args.walks)) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos) throw Error("--walks: '" + item + "' is not SCENE=TRAJECTORY");
    const std::string sceneName = item.substr(0, eq);
    Scene scene;
    try {
      scene = loadScene(sceneName);
    } catch (const Error& e) {
      std::printf("| %s | skipped: %s |\n", sceneName.c_str(), e.what());
      continue;
    }
    const std::vector<TrajectoryFrame> trajectory = loadTrajectory(item.substr(eq + 1));
    StereoRig rig = scene.rig;
    if (!args.eyeSize.empty()) setEyeSize(rig, args.eyeSize);
    std::unique_ptr<FrameRenderer> renderer = makeFrameRenderer(kind, scene);
    const std::vector<std::string> builtins = builtinSceneNames();
    const bool builtin = std::find(builtins.begin(), builtins.end(), sceneName) != builtins.end();
    RenderOptions base;
    base.gather.density.radius = builtin ? RenderOptions().gather.density.radius : args.sceneRadius;
    base.gather.mode = ShadingMode::Full;
    // The profile: PREFIX_<scene>.json from the effects suite if there is one.
    std::string file = scene.name;
    std::replace_if(file.begin(), file.end(), [](char ch) { return !std::isalnum(static_cast<unsigned char>(ch)) && ch != '-'; }, '_');
    const std::string profilePath = args.profiles.empty() ? "" : args.profiles + "_" + file + ".json";
    const bool calibrated = !profilePath.empty() && std::filesystem::exists(profilePath);
    ControlProfile profile = calibrated ? ControlProfile::load(profilePath, scene.effectGroupNames())
                                        : ControlProfile::generic(scene.effectGroupNames());
    const FoveationMask mask = generateFoveationMask(maskParamsForRig(rig));
    // The sampled views' references.
    std::vector<SampledView> views;
    const auto referenceStart = Clock::now();
    for (size_t f = firstView(args); f < trajectory.size(); f += size_t(args.errorEvery)) {
      StereoRig vr = rig;
      vr.head = trajectory[f].head;
      RenderOptions ro = base;
      ro.photonsX = ro.photonsY = 1024;
      ro.gather.punctualShadowRays = 0;
      ro.gather.seed = 0x5eed + uint32_t(f);
      ReferenceSettings settings;
      settings.boxFilter = false;
      ProgressiveReference reference(*renderer, vr, ro, settings);
      for (int i = 0; i < args.referencePasses; ++i) reference.addPass();
      views.push_back({int(f), {reference.image(Eye::Left), reference.image(Eye::Right)}});
    }
    if (views.empty())
      throw Error("--walks: '" + item + "' has " + std::to_string(trajectory.size()) + " frames, fewer than the first sampled view's " +
                  std::to_string(firstView(args) + 1) + " (--error-every / 2)");
    std::printf("| %s | references: %zu views in %.0f s |\n", scene.name.c_str(), views.size(), msSince(referenceStart) / 1000.0);
    std::printf("| %s | %zu frames, %dx%d per eye, radius %g, profile %s, %zu reference views |\n", scene.name.c_str(),
                trajectory.size(), rig.width, rig.height, base.gather.density.radius,
                calibrated ? profilePath.c_str() : "generic (no calibrated profile found)", views.size());
    BudgetControllerParams params;
    params.foveationAvailable = true;
    if (!args.profileOut.empty()) {
      // The quality model fitted on this walk (a single view's error misjudges what the walk's
      // frames show: a short history for the denoiser, the gaze's travel for foveation): the best
      // setting and each knob's step from it alone, walked fixed and compared at the reference
      // views. The costs stay the profile's.
      const BudgetController start(profile, params, base, &mask);
      profile.fitErrors(start.best(), [&](const ControlSetting& s) {
        const RenderOptions o = start.optionsFor(s);
        const Walk w = walk(*renderer, rig, trajectory, views, [&](double) { return o; },
                            [](const StageTimings&, double) {}, args.fixedStride);
        std::printf("| %s | fitting the quality model: %s, mean relMSE %.4f |\n", scene.name.c_str(),
                    BudgetController::toJson(s, profile).dump().c_str(), w.meanError());
        return w.meanError();
      });
      profile.validate();
      const std::string path = args.profileOut + "_" + file + ".json";
      std::ofstream out(path);
      if (!out) throw Error("cannot write '" + path + "'");
      out << profile.toJson().dump(2) << "\n";
      std::printf("| %s | wrote the profile with the walk's quality model, %s; the controller below uses it |\n",
                  scene.name.c_str(), path.c_str());
    }
    std::printf("| scene | budget | policy | frame mean / p50 / p99 | over budget | mean relMSE | meets budget | check |\n"
                "|---|---|---|---|---|---|---|---|\n");
    const BudgetController model(profile, params, base, &mask);  // the ladder's settings and their options
    std::vector<Walk> controlled;
    std::map<std::string, ControlSetting> candidates;
    for (double budget : budgets) {
      params.budgetMs = budget;
      BudgetController controller(profile, params, base, &mask);
      ControlLog log;
      std::optional<ControlDecision> decision;
      Walk w = walk(*renderer, rig, trajectory, views,
                    [&](double now) {
                      decision = controller.decide(now);
                      return controller.optionsFor(decision->setting);
                    },
                    [&](const StageTimings& t, double ms) {
                      controller.observe(ControlCosts::of(t, ms));
                      log.add(*decision, ms, ControlCosts::of(t, ms));
                    });
      for (const auto& [frame, error] : w.error) log.entries()[size_t(frame)].measuredError = error;
      for (const ControlLogEntry& e : log.entries()) ++w.settingFrames[BudgetController::toJson(e.decision.setting, profile).dump()];
      // The settings it spent most time in (at most 3, each at least 3 % of the walk) are run fixed.
      std::vector<std::pair<int, std::string>> used;
      for (const auto& [key, frames] : w.settingFrames) used.push_back({frames, key});
      std::sort(used.rbegin(), used.rend());
      for (size_t u = 0; u < used.size() && u < 3; ++u)
        if (used[u].first >= int(0.03 * double(trajectory.size())))
          for (const ControlLogEntry& e : log.entries())
            if (BudgetController::toJson(e.decision.setting, profile).dump() == used[u].second) {
              candidates[used[u].second] = e.decision.setting;
              break;
            }
      w.name = "controller";
      std::printf("| %s | walked: controller at %.2f ms, p99 %.2f ms, %zu changes |\n", scene.name.c_str(), budget, w.p99(),
                  log.changes());
      w.log = std::move(log);
      controlled.push_back(std::move(w));
      // Its decisions, for the plot.
      json.push_back({{"suite", "controller"}, {"scene", scene.name}, {"budget_ms", budget}, {"policy", "controller"},
                      {"backend", renderer->name()}, {"device", renderer->deviceName()}, {"eye_size", {rig.width, rig.height}},
                      {"profile", calibrated ? profilePath : "generic"}, {"log", controlled.back().log.toJson(controller)}});
    }
    // The uniform ladder: everything at one level, the controller's best photons, radius and denoiser.
    for (int level = int(EffectLevel::Shadows); level < kControlledLevels; ++level) {  // raster: unshadowed suns
      ControlSetting s = model.best();
      for (size_t g = 0; g < profile.groups.size(); ++g) s.levels[g] = uint8_t(std::min<int>(level, s.levels[g]));
      candidates[BudgetController::toJson(s, profile).dump()] = s;
      if (level == int(EffectLevel::Gi)) {  // gi with the fewest photons
        ControlSetting fewer = s;
        fewer.photons = 0;
        candidates[BudgetController::toJson(fewer, profile).dump()] = fewer;
      }
    }
    // The real-time defaults (README's headline frame: 512^2 photons, the asked radius, no
    // denoiser, full resolution, every group at gi): how far the walk is over the budgets without
    // a controller.
    ControlSetting defaults;
    {
      const auto& sides = profile.photonSides;
      defaults.photons = int(std::find(sides.begin(), sides.end(), 512u) - sides.begin());
      const auto& scales = profile.radiusScales;
      defaults.radius = int(std::find(scales.begin(), scales.end(), 1.0f) - scales.begin());
      defaults.levels.fill(uint8_t(EffectLevel::Gi));
      if (defaults.photons < int(sides.size()) && defaults.radius < int(scales.size()))
        candidates[BudgetController::toJson(defaults, profile).dump()] = defaults;
    }
    const std::string defaultsName = BudgetController::toJson(defaults, profile).dump();
    std::vector<std::pair<std::string, Walk>> fixed;
    for (const auto& [key, setting] : candidates) {
      const RenderOptions o = model.optionsFor(setting);
      Walk w = walk(*renderer, rig, trajectory, views, [&](double) { return o; }, [](const StageTimings&, double) {},
                    args.fixedStride);
      w.name = key;
      std::printf("| %s | walked: fixed %s%s, p99 %.2f ms, max %.2f ms |\n", scene.name.c_str(), key == defaultsName ? "(the defaults) " : "",
                  key.c_str(), w.p99(), *std::max_element(w.ms.begin(), w.ms.end()));
      fixed.emplace_back(key, std::move(w));
    }
    for (size_t b = 0; b < budgets.size(); ++b) {
      const double budget = budgets[b];
      const Walk& c = controlled[b];
      double bestFixed = 1e30;
      std::string bestFixedName = "none";
      auto row = [&](const Walk& w, const std::string& name, bool isController) {
        const LatencyStats t = latencyStats(w.ms);
        const bool meets = t.p99 <= budget && w.overFraction(budget) <= 0.005;
        if (!isController && meets && w.meanError() < bestFixed) bestFixed = w.meanError(), bestFixedName = name;
        return std::make_tuple(t, meets);
      };
      for (const auto& [name, w] : fixed) row(w, name, false);
      const auto [ct, cMeets] = row(c, "controller", true);
      const bool ok = cMeets && c.meanError() < bestFixed;
      failures += ok ? 0 : 1;
      std::printf("| %s | %.2f ms | controller (%zu changes) | %.2f / %.2f / %.2f | %.2f %% | %.4f | %s | %s |\n",
                  scene.name.c_str(), budget, c.log.changes(), ct.mean, ct.p50, ct.p99, 100.0 * c.overFraction(budget),
                  c.meanError(), cMeets ? "yes" : "no", ok ? "ok" : "MISSED");
      for (const auto& [name, w] : fixed) {
        const auto [t, meets] = row(w, name, false);
        std::printf("| %s | %.2f ms | fixed %s | %.2f / %.2f / %.2f | %.2f %% | %.4f | %s | %s |\n", scene.name.c_str(),
                    budget, name.c_str(), t.mean, t.p50, t.p99, 100.0 * w.overFraction(budget), w.meanError(),
                    meets ? "yes" : "no",
                    name == bestFixedName ? "best fixed that meets it"
                    : name == defaultsName ? ("the defaults: p99 " + fmt2(t.p99 / budget) + "x, max " + fmt2(*std::max_element(w.ms.begin(), w.ms.end()) / budget) + "x the budget").c_str()
                                           : "");
      }
      json.push_back({{"suite", "controller"}, {"scene", scene.name}, {"budget_ms", budget}, {"policy", "summary"},
                      {"controller", {{"frame", ct}, {"over_fraction", c.overFraction(budget)}, {"mean_rel_mse", c.meanError()},
                                      {"changes", c.log.changes()}}},
                      {"best_fixed", bestFixedName}, {"best_fixed_mean_rel_mse", bestFixed < 1e30 ? bestFixed : -1.0},
                      {"check", ok ? "ok" : "MISSED"}});
    }
    for (const auto& [name, w] : fixed) {
      nlohmann::json frames = w.ms, errors = nlohmann::json::array();
      for (const auto& [frame, error] : w.error) errors.push_back({frame, error});
      json.push_back({{"suite", "controller"}, {"scene", scene.name}, {"policy", "fixed"}, {"setting", nlohmann::json::parse(name)},
                      {"defaults", name == defaultsName},
                      {"frame", latencyStats(w.ms)}, {"mean_rel_mse", w.meanError()}, {"frame_ms", frames},
                      {"frame_stride", args.fixedStride}, {"frame_index", w.frames}, {"errors", errors}});
    }
  }
  return failures;
}

}  // namespace pvr
