#include "effects_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "bench_util.h"
#include "pvr/app/options.h"
#include "pvr/control/budget_controller.h"
#include "pvr/foveation/mask.h"
#include "pvr/image/image_compare.h"
#include "pvr/reference/progressive_reference.h"
#include "pvr/scene/scene.h"
#include "pvr/util/error.h"
#include "pvr/util/latency_stats.h"

namespace pvr {
namespace {

using Clock = std::chrono::steady_clock;

struct Measured {
  LatencyStats frame, rays, density, primary, photons;
  double relMse[2] = {-1, -1};  ///< per eye against the reference (-1: eye not rendered)
  double shadedFraction = 1.0;  ///< shaded samples over pixels (foveation)
  double denoiseMs = 0;
  Image left;  ///< the last frame's left eye
};

Measured measure(FrameRenderer& renderer, const StereoRig& rig, const RenderOptions& o, int warmup, int frames,
                 const Image reference[2], bool resetEachFrame) {
  for (int i = 0; i < warmup; ++i) renderer.render(rig, o, false);
  std::vector<double> frame, rays, density, primary, denoise, photons;
  for (int i = 0; i < frames; ++i) {
    if (resetEachFrame) renderer.resetHistory();
    const auto start = Clock::now();
    const FrameResult f = renderer.render(rig, o, false);
    frame.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    const StageTimings& t = f.timings;
    rays.push_back(t.eyeRayMs[0] + t.eyeRayMs[1]);
    density.push_back(t.densityMs[0] + t.densityMs[1]);
    primary.push_back(t.primaryMs);
    denoise.push_back(t.denoiseMs[0] + t.denoiseMs[1]);
    photons.push_back(t.photonTraceMs + t.mapBuildMs);
  }
  Measured m;
  m.frame = latencyStats(frame), m.rays = latencyStats(rays), m.density = latencyStats(density);
  m.primary = latencyStats(primary);
  m.photons = latencyStats(photons);
  m.denoiseMs = latencyStats(denoise).mean;
  if (resetEachFrame) renderer.resetHistory();
  const FrameResult last = renderer.render(rig, o, true);
  for (int e = 0; e < 2; ++e)
    if (o.eyes[e]) m.relMse[e] = compareToReference(last.eyes[e].image, reference[e]).relMse;
  m.shadedFraction = double(last.shadedSamples[0]) / (double(rig.width) * rig.height);
  m.left = last.eyes[0].image;
  return m;
}

double meanError(const Measured& m) {
  return m.relMse[1] < 0 ? m.relMse[0] : 0.5 * (m.relMse[0] + m.relMse[1]);
}

// Ray-VR's own figures (RTX 2080 with RT cores, HTC Vive, 2x 1080x1200), for context.
const char* kRayVrFigures =
    "Ray-VR (RTX 2080 + Vive): Sun Temple raster + RT shadows 90 fps, RT reflections everywhere 45 fps; Bistro 45 fps";

// The controller's calibration of one scene: each knob's step alone from the best setting.
ControlProfile calibrate(FrameRenderer& renderer, const Scene& scene, const StereoRig& rig, const RenderOptions& base,
                         const Image reference[2], const FrameBenchArgs& args) {
  ControlProfile p = ControlProfile::generic(scene.effectGroupNames());
  p.scene = scene.name, p.device = renderer.deviceName();
  const int frames = std::max(5, args.frames / 4);
  MaskParams maskParams = maskParamsForRig(rig);
  const FoveationMask mask = generateFoveationMask(maskParams);
  BudgetControllerParams cp;
  cp.foveationAvailable = true;
  BudgetController model(p, cp, base, &mask);
  const ControlSetting top = model.best();
  auto run = [&](const ControlSetting& s) {
    RenderOptions o = model.optionsFor(s);
    o.denoise.params.refineWhenStill = false;  // a moving head's denoiser: no refinement
    return measure(renderer, rig, o, 2, frames, reference, o.denoise.enabled);
  };
  // Each setting's run, kept for the costs below; the quality model from their errors.
  std::map<std::string, Measured> runs;
  auto measured = [&](const ControlSetting& s) -> const Measured& {
    const std::string key = BudgetController::toJson(s, p).dump();
    auto it = runs.find(key);
    if (it == runs.end()) it = runs.emplace(key, run(s)).first;
    return it->second;
  };
  p.fitErrors(top, [&](const ControlSetting& s) { return meanError(measured(s)); });
  const Measured& best = measured(top);
  std::printf("| %s | calibration: best setting %s, relMSE %.4f, %.2f ms |\n", scene.name.c_str(),
              BudgetController::toJson(top, p).dump().c_str(), meanError(best), best.frame.mean);
  // The photon and density times of the photon steps, for the costs' affine fits.
  std::vector<double> counts, photonMs, densityMs;
  for (size_t i = 0; i < p.photonSides.size(); ++i) {
    ControlSetting s = top;
    s.photons = int(i);
    const Measured& m = measured(s);
    counts.push_back(double(p.photonSides[i]) * p.photonSides[i]);
    photonMs.push_back(m.photons.mean), densityMs.push_back(m.density.mean);
  }
  // The fixed share of an affine fit a + b N, as a share of its value at the top count.
  auto fixedShare = [&](const std::vector<double>& y) {
    const double n = double(counts.size());
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (size_t i = 0; i < counts.size(); ++i) sx += counts[i], sy += y[i], sxx += counts[i] * counts[i], sxy += counts[i] * y[i];
    const double b = (n * sxy - sx * sy) / std::max(n * sxx - sx * sx, 1e-30), a = (sy - b * sx) / n;
    const double top = a + b * counts.back();
    return top > 0 ? std::clamp(a / top, 0.0, 0.95) : 0.1;
  };
  p.photonFixedShare = fixedShare(photonMs);
  p.densityFixedShare = fixedShare(densityMs);
  double denoiseMs = 0, denoisePasses = 0;
  for (size_t i = 0; i < p.denoiseIterations.size(); ++i) {
    ControlSetting s = top;
    s.denoise = int(i);
    const Measured& m = measured(s);
    if (p.denoiseIterations[i] > 0) denoiseMs += m.denoiseMs, denoisePasses += p.denoisePasses(int(i));
  }
  if (denoisePasses > 0) p.denoiseMsPerIteration = denoiseMs / denoisePasses;
  {
    ControlSetting s = top;
    s.foveated = true;
    const Measured& m = measured(s);
    // The eye pass's time, not its sample count: the foveated pass does not shrink with its samples
    // (on the H200's Sponza 2.6 % of the samples took 8 % of the time).
    const double full = best.rays.mean + best.density.mean, foveated = m.rays.mean + m.density.mean;
    p.foveatedSamples = full > 0 ? std::clamp(foveated / full, 0.01, 1.0) : std::clamp(m.shadedFraction, 0.01, 1.0);
  }
  const double topRays = std::max(best.rays.mean, 1e-6), topDensity = std::max(best.density.mean, 1e-6);
  double shares = 0;
  for (size_t g = 0; g < p.groups.size(); ++g) {
    for (int level = 0; level < kControlledLevels; ++level) {
      if (level == top.levels[g]) continue;
      ControlSetting s = top;
      s.levels[g] = uint8_t(level);
      const Measured& m = measured(s);
      p.levelRayCost[g][size_t(level)] = m.rays.mean / topRays - 1.0;
      if (level == int(EffectLevel::Raster)) p.densityShare[g] = std::clamp(1.0 - m.density.mean / topDensity, 0.0, 1.0);
    }
    shares += p.densityShare[g];
  }
  for (double& s : p.densityShare) s = shares > 0 ? s / shares : 1.0 / double(p.groups.size());
  p.validate();
  return p;
}

}  // namespace

int runEffects(const FrameBenchArgs& args, BackendKind kind, nlohmann::json& json) {
  int failures = 0;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // each row as it is measured (a long suite may be cut short)
  if (args.referencePasses < 2 || args.referencePasses > kMaxReferencePasses)
    throw Error("--reference-passes must be between 2 and " + std::to_string(kMaxReferencePasses));
  std::printf("\nEffect levels (Ray-VR's section V): full shading, hash grid, 512x512 photons, hybrid kernel, %d timed frames "
              "per cell after %d of warm-up; frame mean / p50 / p99 (host wall time, images left on the device), eye rays "
              "and density summed over the eyes, relMSE of each eye against the view's converged reference (%d passes of "
              "1024x1024 photons, kd-tree, all at gi). \"all: L\" = every material at level L; \"G: L, rest: shadows\" = "
              "the effect group G at L and everything else ray-traced shadows.\n%s\n\n",
              args.frames, args.warmup, args.referencePasses, kRayVrFigures);
  std::printf("| scene | eyes | primary | effects | frame mean / p50 / p99 | fps (mean) | eye rays | density | raster pass | "
              "relMSE L / R | check |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& name : splitList(args.effectsScenes)) {
    Scene scene;
    try {
      scene = loadScene(name);
    } catch (const Error& e) {
      std::printf("| %s | skipped: %s |\n", name.c_str(), e.what());
      continue;
    }
    StereoRig rig = scene.rig;
    if (!args.eyeSize.empty()) setEyeSize(rig, args.eyeSize);
    std::unique_ptr<FrameRenderer> renderer = makeFrameRenderer(kind, scene);
    const std::vector<std::string> builtins = builtinSceneNames();
    const bool builtin = std::find(builtins.begin(), builtins.end(), name) != builtins.end();
    RenderOptions o;
    o.photonsX = o.photonsY = 512;
    o.gather.density.radius = builtin ? RenderOptions().gather.density.radius : args.sceneRadius;
    o.gather.mode = ShadingMode::Full;
    Image reference[2];
    {
      RenderOptions ro = o;
      ro.photonsX = ro.photonsY = 1024;
      ro.gather.punctualShadowRays = 0;
      ro.gather.seed = 0x5eed;
      ro.map = PhotonMapKind::KdTree;
      ReferenceSettings settings;
      settings.boxFilter = false;
      ProgressiveReference ref(*renderer, rig, ro, settings);
      for (int i = 0; i < args.referencePasses; ++i) ref.addPass();
      for (int e = 0; e < 2; ++e) reference[e] = ref.image(Eye(e));
    }
    struct Cell {
      std::string effects;
      bool stereo;
      PrimaryVisibility primary;
      GatherParams gather;
    };
    std::vector<Cell> cells;
    for (int level = 0; level < kEffectLevels; ++level) {
      GatherParams g = o.gather;
      g.overrideEffects = true;
      g.effects = EffectLevel(level);
      const std::string label = std::string("all: ") + effectLevelName(EffectLevel(level));
      cells.push_back({label, true, PrimaryVisibility::Rays, g});
      cells.push_back({label, true, PrimaryVisibility::Raster, g});
      cells.push_back({label, false, PrimaryVisibility::Rays, g});
    }
    const std::vector<std::string>& groups = scene.effectGroupNames();
    for (size_t group = 1; group < groups.size(); ++group)
      for (EffectLevel level : {EffectLevel::Reflections, EffectLevel::Gi}) {
        GatherParams g = o.gather;
        for (size_t other = 0; other < groups.size(); ++other) g.groupEffects[other] = uint8_t(EffectLevel::Shadows);
        g.groupEffects[group] = uint8_t(level);
        cells.push_back({groups[group] + ": " + effectLevelName(level) + ", rest: shadows", true, PrimaryVisibility::Rays, g});
      }
    double stereoLeft[kEffectLevels] = {}, raysError[kEffectLevels] = {};
    bool rasterAvailable = true;
    for (size_t c = 0; c < cells.size(); ++c) {
      const Cell& cell = cells[c];
      if (cell.primary == PrimaryVisibility::Raster && !rasterAvailable) continue;
      RenderOptions co = o;
      co.gather = cell.gather;
      co.primary = cell.primary;
      co.eyes[1] = cell.stereo;
      Measured m;
      try {
        m = measure(*renderer, rig, co, args.warmup, args.frames, reference, false);
      } catch (const Error& e) {  // no Vulkan device for the pre-pass: say so, measure the rest
        if (cell.primary != PrimaryVisibility::Raster) throw;
        rasterAvailable = false;
        std::printf("| %s | raster pre-pass skipped: %s |\n", scene.name.c_str(), e.what());
        continue;
      }
      // Checks: mono's left eye is stereo's (the eyes are independent at --stereo separate); the
      // pre-pass changes sample 0's first hits only (same error within noise); gi is no further
      // from the reference than raster.
      bool ok = std::isfinite(m.relMse[0]) && m.frame.mean > 0;
      const int level = cell.gather.overrideEffects ? int(cell.gather.effects) : -1;
      if (level >= 0 && cell.stereo && cell.primary == PrimaryVisibility::Rays) stereoLeft[level] = m.relMse[0], raysError[level] = meanError(m);
      if (level >= 0 && !cell.stereo) ok = ok && std::fabs(m.relMse[0] - stereoLeft[level]) <= 1e-3 * stereoLeft[level] + 1e-9;
      if (level >= 0 && cell.primary == PrimaryVisibility::Raster)
        ok = ok && std::fabs(meanError(m) - raysError[level]) <= 0.1 * raysError[level] + 0.002;
      if (level == int(EffectLevel::Gi) && cell.stereo && cell.primary == PrimaryVisibility::Rays)
        ok = ok && raysError[int(EffectLevel::Gi)] <= raysError[int(EffectLevel::Raster)];
      failures += ok ? 0 : 1;
      char err[64];
      if (cell.stereo) std::snprintf(err, sizeof err, "%.4f / %.4f", m.relMse[0], m.relMse[1]);
      else std::snprintf(err, sizeof err, "%.4f / -", m.relMse[0]);
      std::printf("| %s | %s | %s | %s | %.2f / %.2f / %.2f | %.0f | %.2f | %.2f | %s | %s | %s |\n", scene.name.c_str(),
                  cell.stereo ? "stereo" : "mono (left)", primaryVisibilityName(cell.primary), cell.effects.c_str(),
                  m.frame.mean, m.frame.p50, m.frame.p99, 1000.0 / m.frame.mean, m.rays.mean, m.density.mean,
                  cell.primary == PrimaryVisibility::Raster ? (std::to_string(m.primary.mean).substr(0, 5) + " ms").c_str() : "-",
                  err, ok ? "ok" : "MISMATCH");
      nlohmann::json row = {{"suite", "effects"}, {"scene", scene.name}, {"backend", renderer->name()},
                            {"device", renderer->deviceName()}, {"eye_size", {rig.width, rig.height}},
                            {"photons", o.photonCount()}, {"radius", o.gather.density.radius},
                            {"eyes", cell.stereo ? "stereo" : "mono"}, {"primary", primaryVisibilityName(cell.primary)},
                            {"effects", cell.effects}, {"frames", args.frames}, {"frame", m.frame}, {"eye_rays", m.rays},
                            {"density", m.density}, {"raster_prepass", m.primary},
                            {"rel_mse_vs_reference", {m.relMse[0], m.relMse[1]}}, {"reference_passes", args.referencePasses},
                            {"check", ok ? "ok" : "MISMATCH"}};
      json.push_back(row);
    }
    if (!args.profileOut.empty()) {
      const ControlProfile profile = calibrate(*renderer, scene, rig, o, reference, args);
      std::string file = scene.name;
      std::replace_if(file.begin(), file.end(), [](char ch) { return !std::isalnum(static_cast<unsigned char>(ch)) && ch != '-'; }, '_');
      const std::string path = args.profileOut + "_" + file + ".json";
      std::ofstream out(path);
      if (!out) throw Error("cannot write '" + path + "'");
      out << profile.toJson().dump(2) << "\n";
      std::printf("| %s | wrote the controller's profile %s |\n", scene.name.c_str(), path.c_str());
    }
  }
  return failures;
}

}  // namespace pvr
