#include "pvr/app/cli.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <new>
#include <memory>
#include <regex>
#include <chrono>
#include <csignal>
#include <fstream>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "frame_bench.h"
#include "pvr/app/options.h"
#include "pvr/foveation/gaze.h"
#include "pvr/foveation/mask.h"
#include "pvr/app/loop_commands.h"
#include "pvr/app/soak.h"
#include "pvr/app/trajectory.h"
#include "map_bench.h"
#include "pvr/image/image_compare.h"
#include "pvr/image/image_io.h"
#include "pvr/reference/progressive_reference.h"
#include "pvr/render/renderer.h"
#include "pvr/scene/scene.h"
#include "pvr/util/error.h"
#include "pvr/util/fault_injection.h"
#include "pvr/util/json_number.h"

namespace pvr {
namespace {

struct Size2 {
  long long x = 0, y = 0;
};

// Emitted photons: "WxH" (the paper's 256x256), or a single number N meaning N photons.
Size2 parsePhotonGrid(const std::string& text) {
  static const std::regex pair(R"(^\s*(\d{1,9})\s*[xX]\s*(\d{1,9})\s*$)");
  static const std::regex single(R"(^\s*(\d{1,12})\s*$)");
  std::smatch m;
  if (std::regex_match(text, m, pair)) return {std::stoll(m[1]), std::stoll(m[2])};
  if (std::regex_match(text, m, single)) return {std::stoll(m[1]), 1};
  throw Error("--photons must be WxH with positive integers, got '" + text + "'");
}

float parseFloat(const std::string& text, const std::string& what) {
  try {
    size_t used = 0;
    float v = std::stof(text, &used);
    if (used != text.size()) throw std::invalid_argument(text);
    return v;
  } catch (const std::exception&) {
    throw Error(what + " must be a number, got '" + text + "'");
  }
}

// Creates the folder an output file goes into; a clear error if it cannot be made.
void ensureParentDirectory(const std::string& file) {
  std::filesystem::path parent = std::filesystem::path(file).parent_path();
  if (parent.empty()) return;
  std::error_code error;
  std::filesystem::create_directories(parent, error);
  if (error) throw Error("cannot write '" + file + "': cannot create folder '" + parent.string() + "' (" + error.message() + ")");
}

struct RenderArgs {
  std::string scene = "cornell";
  std::string photons = "256x256";
  std::string radius;  // empty: 0.05 for the built-in scenes, else 0.4 % of the scene's bounding-box diagonal
  std::string map = "hashgrid";
  std::string estimator = "radius";
  std::string boundary = "sphere";
  std::string kernel = "hybrid";
  std::string density = "pixel";
  std::string cacheCell;  // empty: kDefaultCacheCellFraction
  std::string primary = "rays";
  std::string effects;  // empty: each material's own level (the scene's "effect"s)
  std::string backend = "auto";
  std::string stereo = "separate";
  int k = 32;
  std::string eyes = "both";
  std::string eyeSize;  // empty: the scene's rig (1440x1600 for built-in scenes)
  std::string ipd;      // empty: the scene's rig (63 mm)
  int spp = 1;
  uint32_t seed = 1;
  std::string sampling = "blue-noise";
  int photonDepth = 8;
  int specularDepth = 8;
  int shadowRays = 1;  // to the punctual lights per gather point; 0: one per light
  std::string shading = "full";
  bool foveated = false;
  std::string mask;          // empty: made for the rig at start
  std::string gaze = "0.5,0.5";
  std::string trajectory;    // one frame per line: head pose + gaze
  bool taa = false;
  std::string taaBlend;      // empty: TaaParams' default
  bool denoise = false;
  int denoiseIterations = DenoiseParams().iterations;
  int denoiseDirectIterations = DenoiseParams().directIterations;
  bool noRefine = false;
  std::string denoiseHistory;  // empty: DenoiseParams' default
  std::string denoisePhotonPasses;  // empty: DenoiseParams' default
  int photonBatches = 1;     // a rolling photon map's slices, one retraced per frame
  std::string out = "out/render";
  float exposure = 1.0f;
  std::string acuity = "linear";  // the mask made at start under --foveated
  std::string settings;           // JSON settings file (the viewer writes them)
  std::optional<Pose> head;       // from the settings file
  std::string budget;             // --budget-ms: milliseconds or "display"; empty: no controller
  std::string controllerProfile;  // its calibrated profile (empty: the generic model)
};

void addBudgetOptions(CLI::App& cmd, RenderArgs& a) {
  cmd.add_option("--budget-ms", a.budget,
                 "Frame budget in ms (11.1 at 90 Hz), or 'display' for the display's frame period (xr: the runtime's; "
                 "view: the monitor's refresh): the controller chooses photons, radius, foveation, denoiser and "
                 "each effect group's level per frame to keep the p99 frame time under it (docs/ray-vr.md)");
  cmd.add_option("--controller-profile", a.controllerProfile,
                 "The controller's calibrated cost and quality model (from `bench --suite effects --profile-out`; "
                 "default: a generic model)");
}

// The settings file: the command line's options by name ("radius": "0.05"), the head pose and the
// gaze. Options given on the command line win over the file's.
void applySettings(const std::string& path, RenderArgs& a, const CLI::App& cmd) {
  std::ifstream in(path);
  if (!in) throw Error("cannot read settings file '" + path + "'");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    throw Error("settings file '" + path + "' is not valid JSON: " + std::string(e.what()).substr(0, 120));
  }
  if (!j.is_object()) throw Error("settings file '" + path + "' must hold a JSON object");
  // An option the command does not have (the reference has no --foveated) counts as not given.
  auto given = [&](const char* flag) { return cmd.get_option_no_throw(flag) != nullptr && cmd.count(flag) > 0; };
  try {
    auto text = [&](const char* key, const char* flag, std::string& field) {
      if (j.contains(key) && !given(flag)) field = j[key].is_string() ? j[key].get<std::string>() : j[key].dump();
    };
    auto flag = [&](const char* key, const char* f, bool& field) {
      if (j.contains(key) && !given(f)) field = j[key].get<bool>();
    };
    text("photons", "--photons", a.photons);
    text("radius", "--radius", a.radius);
    text("map", "--map", a.map);
    text("estimator", "--estimator", a.estimator);
    text("boundary", "--boundary", a.boundary);
    text("kernel", "--kernel", a.kernel);
    text("density", "--density", a.density);
    text("cache_cell", "--cache-cell", a.cacheCell);
    text("primary", "--primary", a.primary);
    text("effects", "--effects", a.effects);
    text("backend", "--backend", a.backend);
    text("stereo", "--stereo", a.stereo);
    text("eye_size", "--eye-size", a.eyeSize);
    text("ipd", "--ipd", a.ipd);
    text("gaze", "--gaze", a.gaze);
    text("acuity", "--acuity", a.acuity);
    text("taa_blend", "--taa-blend", a.taaBlend);
    flag("foveated", "--foveated", a.foveated);
    flag("taa", "--taa", a.taa);
    flag("denoise", "--denoise", a.denoise);
    text("denoise_history", "--denoise-history", a.denoiseHistory);
    text("denoise_photon_passes", "--denoise-photon-passes", a.denoisePhotonPasses);
    if (j.contains("denoise_iterations") && !given("--denoise-iterations"))
      a.denoiseIterations = jsonNumber<int>(j["denoise_iterations"], "denoise_iterations");
    if (j.contains("denoise_direct_iterations") && !given("--denoise-direct-iterations"))
      a.denoiseDirectIterations = jsonNumber<int>(j["denoise_direct_iterations"], "denoise_direct_iterations");
    if (j.contains("k") && !given("--k")) a.k = jsonNumber<int>(j["k"], "k");
    if (j.contains("exposure") && !given("--exposure")) a.exposure = jsonNumber<float>(j["exposure"], "exposure");
    if (j.contains("scene") && !given("scene")) a.scene = j["scene"].get<std::string>();
    if (j.contains("head")) {
      const auto& p = j["head"].at("position");
      const auto& q = j["head"].at("orientation");
      Pose head;
      auto number = [](const nlohmann::json& n) { return jsonNumber<float>(n, "the head pose"); };
      head.position = {number(p.at(0)), number(p.at(1)), number(p.at(2))};
      head.orientation = {number(q.at(0)), number(q.at(1)), number(q.at(2)), number(q.at(3))};
      float n = std::sqrt(head.orientation.x * head.orientation.x + head.orientation.y * head.orientation.y +
                          head.orientation.z * head.orientation.z + head.orientation.w * head.orientation.w);
      if (!(n > 1e-6f) || !std::isfinite(n) || !std::isfinite(head.position.x + head.position.y + head.position.z))
        throw Error("the head pose must be finite with a non-zero quaternion");
      head.orientation = {head.orientation.x / n, head.orientation.y / n, head.orientation.z / n, head.orientation.w / n};
      a.head = head;
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error("settings file '" + path + "': a value has the wrong type or is missing (" + std::string(e.what()).substr(0, 100) + ")");
  } catch (const Error& e) {
    throw Error("settings file '" + path + "': " + e.what());
  }
}

void addRenderOptions(CLI::App& cmd, RenderArgs& a) {
  cmd.add_option("--photons", a.photons, "Emitted photons as WxH (the paper's 128x128 .. 512x512) or a count")
      ->capture_default_str();
  cmd.add_option("--radius", a.radius,
                 "Search radius of density estimation (the maximum radius for kNN), scene units (default: 0.05 for the "
                 "built-in scenes, 0.4% of the bounding-box diagonal for others)")
      ->capture_default_str();
  cmd.add_option("--map", a.map, "Photon map: hashgrid | kdtree")->capture_default_str();
  cmd.add_option("--estimator", a.estimator, "Density estimation: radius (fixed radius, no heap) | knn (max-heap)")
      ->capture_default_str();
  cmd.add_option("--k", a.k, "Photons per kNN estimate (1..64)")->capture_default_str();
  cmd.add_option("--boundary", a.boundary,
                 "Estimates where a surface meets a wall: sphere (the paper's: the photons within r, over pi r^2) | "
                 "clipped (probe rays find the walls and edges in reach: photons on or behind the nearest wall are "
                 "left out, and the estimate is over the disc's area on the surface; docs/reference.md)")
      ->capture_default_str();
  cmd.add_option("--kernel", a.kernel,
                 "GPU eye pass: single (rays + estimate in one kernel) | hybrid (separate density kernel) | shared "
                 "(hybrid, the paper's Algorithm 1) | sorted (hybrid, gather points sorted by cell); same image")
      ->capture_default_str();
  cmd.add_option("--density", a.density,
                 "Photon-map estimates: pixel (one per gather point, the paper's) | cache (one per surface cell of "
                 "side --cache-cell x radius, interpolated by the pixels and eyes near it; glossy points per pixel)")
      ->capture_default_str();
  cmd.add_option("--cache-cell", a.cacheCell, "The surface cache's cell side as a fraction of the radius (0.01..1, "
                                              "default 0.25)");
  cmd.add_option("--primary", a.primary,
                 "First hits of the eye rays: rays (traced) | raster (Ray-VR's G-buffer pre-pass: both eyes rasterised "
                 "by Vulkan in one multiview pass, on the CUDA GPU or, for the CPU backend, any Vulkan device)")
      ->capture_default_str();
  cmd.add_option("--effects", a.effects,
                 "Ray-VR's effect level for every material, overriding the scene's: raster (direct light, no shadows) | "
                 "shadows | reflections (mirrors, glass, glossy followed) | gi (photon-mapped, the default) | path "
                 "(indirect light path traced); or per effect group of the scene, GROUP=LEVEL,... (e.g. "
                 "floor=reflections,rest=shadows; \"rest\": the materials in no group)");
  cmd.add_option("--backend", a.backend, "cpu (Embree + TBB reference) | cuda | auto (cuda if a GPU is present)")
      ->capture_default_str();
  cmd.add_option("--stereo", a.stereo,
                 "Right eye: separate (shaded on its own) | scatter (the paper's: left hit points projected into the "
                 "right image) | gather (ours: right hits looked up in the left image); reuse is for diffuse surfaces only")
      ->capture_default_str();
  cmd.add_option("--seed", a.seed, "Seed of the counter-based random numbers")->capture_default_str();
  cmd.add_option("--sampling", a.sampling,
                 "A pixel's first random numbers (sub-pixel position, light sample): blue-noise (dithered by a "
                 "void-and-cluster mask, low-discrepancy from frame to frame) | white (independent)")
      ->capture_default_str();
  cmd.add_option("--photon-depth", a.photonDepth, "Maximum surface interactions per photon path")->capture_default_str();
  cmd.add_option("--shadow-rays", a.shadowRays,
                 "Shadow rays to the point and spot lights per shaded point, each to one light chosen by its "
                 "unoccluded contribution (unbiased); suns always get one ray each; 0: one exact ray to every light")
      ->capture_default_str();
}

// What the commands that write images of a view (render, reference) share: the scene, the render
// options, the eyes and rig, samples, shading and exposure.
// The denoiser's options (render, xr, view).
void addDenoiseOptions(CLI::App& cmd, RenderArgs& a) {
  cmd.add_flag("--denoise", a.denoise,
               "Spatio-temporal denoising (SVGF) before TAA: direct and photon-map light demodulated by albedo, "
               "accumulated over frames by reprojection, filtered by an edge-aware a-trous wavelet");
  cmd.add_option("--denoise-iterations", a.denoiseIterations,
                 "A-trous passes of --denoise (0: temporal accumulation only; at most 8)")
      ->capture_default_str();
  cmd.add_option("--denoise-direct-iterations", a.denoiseDirectIterations,
                 "Of those passes, how many filter the direct (shadow-ray) light; the photon-map light takes them all "
                 "(1..8; more than --denoise-iterations: all)")
      ->capture_default_str();
  cmd.add_option("--photon-batches", a.photonBatches,
                 "A rolling photon map: the photons in N slices, one retraced per frame, so consecutive frames share "
                 "all but one (1/N of the photon tracing a frame; on the H200 it did not lower the flicker and "
                 "raised the error, docs/denoising.md; 1..64, 1: all photons every frame)")
      ->capture_default_str();
  cmd.add_option("--denoise-history", a.denoiseHistory,
                 "How --denoise reads the last frame's history under a moving head: bilinear (2x2 taps) | "
                 "catmull-rom (sharper: 12 taps where they all saw the surface; on the H100 3 % less error on "
                 "Sponza for 0.22 ms more a stereo frame)")
      ->default_str(DenoiseParams().bicubicHistory ? "catmull-rom" : "bilinear");
  cmd.add_option("--denoise-photon-passes", a.denoisePhotonPasses,
                 "Where --denoise's passes after the first filter the photon-map light: full (every pixel) | quarter "
                 "(the even pixels, exact there; the others interpolated from them on their surface; "
                 "docs/denoising.md)")
      ->default_str(DenoiseParams().quarterPhotonPasses ? "quarter" : "full");
  cmd.add_flag("--no-refine", a.noRefine,
               "With --denoise: no progressive refinement while the head is still (averaging still frames with a "
               "shrinking photon radius)");
}

void addImageCommandOptions(CLI::App& cmd, RenderArgs& a, const char* sppHelp) {
  cmd.add_option("scene", a.scene, "Built-in scene name or scene/mesh file")->capture_default_str();
  addRenderOptions(cmd, a);
  cmd.add_option("--eyes", a.eyes, "Eyes to render: left | right | both")->capture_default_str();
  cmd.add_option("--eye-size", a.eyeSize, "Per-eye resolution WxH (default: the scene's rig, 1440x1600)");
  cmd.add_option("--ipd", a.ipd, "Interpupillary distance in metres (default: the scene's rig, 0.063)");
  cmd.add_option("--spp", a.spp, sppHelp)->capture_default_str();
  cmd.add_option("--specular-depth", a.specularDepth, "Mirror/glass bounces followed from the eye")->capture_default_str();
  cmd.add_option("--shading", a.shading,
                 "full (direct light by shadow rays + photon map for caustics/indirect) | photons (photon map "
                 "alone, the paper's formulation)")
      ->capture_default_str();
  cmd.add_option("--exposure", a.exposure, "Scale applied before the sRGB PNG's clamp")->capture_default_str();
}

// The render options from their spellings: syntax here, ranges in validateOptions (one place).
RenderOptions toOptions(const RenderArgs& a, StereoRig& rig) {
  RenderOptions o;
  Size2 photons = parsePhotonGrid(a.photons);
  if (photons.x > 0xffffffffll || photons.y > 0xffffffffll || photons.x * photons.y > 0xffffffffll)
    throw Error("--photons: too many photons: '" + a.photons + "' (at most " + std::to_string(kMaxPhotons) + ", 8192x8192)");
  o.photonsX = uint32_t(photons.x);
  o.photonsY = uint32_t(photons.y);
  o.gather.density.radius = a.radius.empty() ? 0.05f : parseFloat(a.radius, "--radius");
  if (a.map == "hashgrid") o.map = PhotonMapKind::HashGrid;
  else if (a.map == "kdtree") o.map = PhotonMapKind::KdTree;
  else throw Error("--map must be hashgrid or kdtree, got '" + a.map + "'");
  if (a.estimator == "radius") o.gather.density.estimator = Estimator::Radius;
  else if (a.estimator == "knn") o.gather.density.estimator = Estimator::Knn;
  else throw Error("--estimator must be radius or knn, got '" + a.estimator + "'");
  if (a.boundary == "sphere") o.gather.density.boundary = Boundary::Sphere;
  else if (a.boundary == "clipped") o.gather.density.boundary = Boundary::Clipped;
  else throw Error("--boundary must be sphere or clipped, got '" + a.boundary + "'");
  o.gather.density.k = a.k;
  if (a.kernel == "single") o.kernel = DensityKernel::Single;
  else if (a.kernel == "hybrid") o.kernel = DensityKernel::Hybrid;
  else if (a.kernel == "shared") o.kernel = DensityKernel::SharedMemory;
  else if (a.kernel == "sorted") o.kernel = DensityKernel::CellSorted;
  else throw Error("--kernel must be single, hybrid, shared or sorted, got '" + a.kernel + "'");
  if (a.density == "pixel") o.density = DensityScheme::PerPixel;
  else if (a.density == "cache") o.density = DensityScheme::SurfaceCache;
  else throw Error("--density must be pixel or cache, got '" + a.density + "'");
  if (!a.cacheCell.empty()) o.cacheCellFraction = parseFloat(a.cacheCell, "--cache-cell");
  if (a.primary == "rays") o.primary = PrimaryVisibility::Rays;
  else if (a.primary == "raster") o.primary = PrimaryVisibility::Raster;
  else throw Error("--primary must be rays or raster, got '" + a.primary + "'");
  if (!a.effects.empty() && a.effects.find('=') == std::string::npos) {  // GROUP=LEVEL lists: setUpRender, with the scene
    if (!effectLevelFromName(a.effects, o.gather.effects))
      throw Error("--effects must be raster, shadows, reflections, gi or path, or GROUP=LEVEL,..., got '" + a.effects + "'");
    o.gather.overrideEffects = true;
  }
  o.stereo = parseStereoMode(a.stereo);
  if (a.eyes == "both") o.eyes[0] = o.eyes[1] = true;
  else if (a.eyes == "left") o.eyes[0] = true, o.eyes[1] = false;
  else if (a.eyes == "right") o.eyes[0] = false, o.eyes[1] = true;
  else throw Error("--eyes must be left, right or both, got '" + a.eyes + "'");
  if (!a.eyeSize.empty()) setEyeSize(rig, a.eyeSize);
  if (!a.ipd.empty()) {
    rig.ipd = parseFloat(a.ipd, "--ipd");
  }
  o.gather.samplesPerPixel = a.spp;
  o.gather.seed = a.seed;
  if (a.sampling == "blue-noise") o.gather.sampling = PixelSampling::BlueNoise;
  else if (a.sampling == "white") o.gather.sampling = PixelSampling::White;
  else throw Error("--sampling must be blue-noise or white, got '" + a.sampling + "'");
  o.maxPhotonDepth = a.photonDepth;
  o.gather.maxSpecularDepth = a.specularDepth;
  o.gather.punctualShadowRays = a.shadowRays;
  if (a.shading == "full") o.gather.mode = ShadingMode::Full;
  else if (a.shading == "photons") o.gather.mode = ShadingMode::PhotonMapOnly;
  else throw Error("--shading must be full or photons, got '" + a.shading + "'");
  if (!(a.exposure > 0.0f) || !std::isfinite(a.exposure)) throw Error("--exposure must be a positive number");
  return o;
}

// --effects GROUP=LEVEL,...: the levels of the scene's effect groups ("rest": the materials in none).
void setGroupEffects(const std::string& spec, const Scene& scene, GatherParams& gather) {
  std::stringstream items(spec);
  for (std::string item; std::getline(items, item, ',');) {
    const size_t eq = item.find('=');
    EffectLevel level;
    if (eq == std::string::npos || !effectLevelFromName(item.substr(eq + 1), level))
      throw Error("--effects: '" + item + "' is not GROUP=LEVEL (levels: raster, shadows, reflections, gi, path)");
    const int group = scene.effectGroupIndex(item.substr(0, eq));
    if (group < 0) {
      std::string names;
      for (const std::string& n : scene.effectGroupNames()) names += (names.empty() ? "" : ", ") + n;
      throw Error("--effects: the scene has no effect group '" + item.substr(0, eq) + "' (it has: " + names + ")");
    }
    gather.groupEffects[group] = uint8_t(level);
  }
}

// What every command that renders needs, made from the options: the scene, the rig, the
// validated options and the foveation mask they point at.
struct RenderSetup {
  BackendKind backend = BackendKind::Auto;
  Scene scene;
  StereoRig rig;
  RenderOptions options;
  FoveationMask mask;
  std::vector<TrajectoryFrame> trajectory;
};

// The options from the command line alone, every check that needs no scene, device or file but
// the settings already read: what `CliRun::CheckOnly` runs (the command-line fuzz harness).
RenderOptions optionsFromArgs(const RenderArgs& a, StereoRig& rig) {
  RenderOptions options = toOptions(a, rig);
  if (a.acuity != "linear" && a.acuity != "geisler-perry")
    throw Error("--acuity must be linear or geisler-perry, got '" + a.acuity + "'");
  if (a.foveated) {
    float gx = 0, gy = 0;
    char extra = 0;
    if (std::sscanf(a.gaze.c_str(), "%f,%f%c", &gx, &gy, &extra) != 2)
      throw Error("--gaze must be X,Y (image fractions, 0.5,0.5 = centre), got '" + a.gaze + "'");
    options.foveation.gaze[0][0] = gx, options.foveation.gaze[0][1] = gy;
  } else if (!a.mask.empty()) {
    throw Error("--mask is for --foveated rendering");
  }
  if (!a.taaBlend.empty() && !a.taa) throw Error("--taa-blend is for --taa");
  if (a.taa) {
    options.temporal.enabled = true;
    if (!a.taaBlend.empty()) options.temporal.taa.blend = parseFloat(a.taaBlend, "--taa-blend");
  }
  if (a.denoiseIterations != DenoiseParams().iterations && !a.denoise)
    throw Error("--denoise-iterations is for --denoise");
  if (a.denoiseDirectIterations != DenoiseParams().directIterations && !a.denoise)
    throw Error("--denoise-direct-iterations is for --denoise");
  if (a.noRefine && !a.denoise) throw Error("--no-refine is for --denoise");
  if (!a.denoiseHistory.empty()) {
    if (!a.denoise) throw Error("--denoise-history is for --denoise");
    if (a.denoiseHistory != "catmull-rom" && a.denoiseHistory != "bilinear")
      throw Error("--denoise-history must be catmull-rom or bilinear, got '" + a.denoiseHistory + "'");
    options.denoise.params.bicubicHistory = a.denoiseHistory == "catmull-rom";
  }
  if (!a.denoisePhotonPasses.empty()) {
    if (!a.denoise) throw Error("--denoise-photon-passes is for --denoise");
    if (a.denoisePhotonPasses != "full" && a.denoisePhotonPasses != "quarter")
      throw Error("--denoise-photon-passes must be full or quarter, got '" + a.denoisePhotonPasses + "'");
    options.denoise.params.quarterPhotonPasses = a.denoisePhotonPasses == "quarter";
  }
  options.denoise.params.refineWhenStill = !a.noRefine;
  options.denoise.enabled = a.denoise;
  options.denoise.params.iterations = a.denoiseIterations;
  options.denoise.params.directIterations = a.denoiseDirectIterations;
  options.photonBatches = a.photonBatches;
  validateOptions(options, rig);  // before the scene-dependent work: a bad value need not wait for it
  return options;
}

std::unique_ptr<RenderSetup> setUpRender(const RenderArgs& a) {
  auto setup = std::make_unique<RenderSetup>();
  setup->backend = parseBackendKind(a.backend);
  setup->scene = loadScene(a.scene);
  Scene& scene = setup->scene;
  StereoRig& rig = setup->rig;
  rig = scene.rig;
  if (a.head) rig.head = *a.head;
  RenderOptions& options = setup->options;
  options = optionsFromArgs(a, rig);
  if (a.effects.find('=') != std::string::npos) setGroupEffects(a.effects, scene, options.gather);
  const std::vector<std::string> builtins = builtinSceneNames();
  if (a.radius.empty() && std::find(builtins.begin(), builtins.end(), a.scene) == builtins.end()) {
    Bounds3 b = scene.bounds();  // a scene of any size: the radius follows it
    options.gather.density.radius = std::max(0.004f * length(b.extent()), 1e-6f);
  }
  FoveationMask& mask = setup->mask;
  if (a.foveated) {
    MaskParams params = maskParamsForRig(rig);
    if (a.acuity == "geisler-perry") params.acuity.kind = AcuityKind::GeislerPerry;
    mask = a.mask.empty() ? generateFoveationMask(params) : loadFoveationMask(a.mask);
    options.foveation.mask = &mask;
    options.foveation.verge = true;  // both eyes fixate what the left eye's gaze meets
  }
  validateOptions(options, rig);  // again, with the scene's radius and the mask
  if (!a.trajectory.empty()) setup->trajectory = loadTrajectory(a.trajectory);
  if (scene.skippedTriangles() > 0)
    std::cerr << "photonvr: warning: skipped " << scene.skippedTriangles()
              << " degenerate or non-finite triangles\n";
  return setup;
}

int runRender(const RenderArgs& a) {
  std::unique_ptr<RenderSetup> setup = setUpRender(a);
  Scene& scene = setup->scene;
  StereoRig& rig = setup->rig;
  RenderOptions& options = setup->options;
  const FoveationMask& mask = setup->mask;
  const std::vector<TrajectoryFrame>& trajectory = setup->trajectory;
  ensureParentDirectory(a.out);  // before the work, not after it
  std::unique_ptr<FrameRenderer> renderer = makeFrameRenderer(setup->backend, scene);
  std::printf("scene %s: %u triangles, %u emitting, %zu point/spot/sun lights, %u textures; eyes %dx%d, IPD %.1f mm\n",
              scene.name.c_str(), scene.triangleCount(), scene.lightTriangleCount(), scene.punctualLights().size(),
              scene.textureCount(), rig.width, rig.height, rig.ipd * 1000.0f);
  std::printf("photons %ux%u, radius %g, map %s, estimator %s%s%s, %d spp, %d shadow rays per point (0: one per light), %s sampling, seed %u\n", options.photonsX,
              options.photonsY, options.gather.density.radius, a.map.c_str(), a.estimator.c_str(),
              options.gather.density.estimator == Estimator::Knn ? (" (k=" + std::to_string(a.k) + ")").c_str() : "",
              options.gather.density.boundary == Boundary::Clipped ? " clipped at walls and edges" : "",
              options.gather.samplesPerPixel, options.gather.punctualShadowRays,
              options.gather.sampling == PixelSampling::BlueNoise ? "blue-noise" : "white", options.gather.seed);
  std::printf("backend %s: %s%s\n", renderer->name().c_str(), renderer->deviceName().c_str(),
              renderer->name() == "cuda" ? (", " + std::string(densityKernelName(options.kernel)) + " kernel").c_str() : "");
  const char* names[2] = {"left", "right"};
  const BudgetSpec budget = parseBudget(a.budget);
  if (budget.enabled() && trajectory.empty()) throw Error("--budget-ms is for --trajectory (and xr, view)");
  if (budget.followsDisplay)
    throw Error("--budget-ms display needs a display (xr or view); render --trajectory has none: give milliseconds");
  if (!trajectory.empty()) {  // one frame per pose, PREFIX_NNNN_left/right
    double totalMs = 0;
    std::optional<FoveationMask> controlMask;
    std::unique_ptr<BudgetController> controller =
        budget.enabled() ? makeBudgetController(budget, a.controllerProfile, scene, options, rig, a.acuity, controlMask)
                       : nullptr;
    ControlLog control;
    const auto start = std::chrono::steady_clock::now();
    for (size_t f = 0; f < trajectory.size(); ++f) {
      rig.head = trajectory[f].head;
      std::optional<ControlDecision> decision;
      if (controller) {
        decision = controller->decide(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        options = controller->optionsFor(decision->setting);
      }
      copyGaze(trajectory[f], options.foveation);
      const auto frameStart = std::chrono::steady_clock::now();
      FrameResult frame = renderer->render(rig, options);
      if (controller) {  // the frame's time: the pipeline's, images read back
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - frameStart).count();
        controller->observe(ControlCosts::of(frame.timings, ms));
        control.add(*decision, ms, ControlCosts::of(frame.timings, ms));
      }
      totalMs += frame.timings.totalMs();
      char prefix[32];
      std::snprintf(prefix, sizeof prefix, "_%04zu", f);
      std::printf("frame %4zu: %8.2f ms (left eye %.2f, right eye %.2f), %zu + %zu samples shaded", f,
                  frame.timings.totalMs(), frame.timings.eyeMs[0], frame.timings.eyeMs[1], frame.shadedSamples[0],
                  frame.shadedSamples[1]);
      if (options.temporal.enabled) {
        double pixels = double(rig.width) * rig.height * ((options.eyes[0] ? 1 : 0) + (options.eyes[1] ? 1 : 0));
        std::printf(", TAA history kept on %.1f%% of pixels", 100.0 * double(frame.historyPixels[0] + frame.historyPixels[1]) / pixels);
      }
      std::printf("\n");
      for (int e = 0; e < 2; ++e)
        if (options.eyes[e])
          for (const char* ext : {".png", ".exr"}) writeImage(frame.eyes[e].image, a.out + prefix + "_" + names[e] + ext, a.exposure);
    }
    std::printf("%zu frames, %.2f ms per frame on average; wrote %s_NNNN_left/right.png/.exr\n", trajectory.size(),
                totalMs / double(trajectory.size()), a.out.c_str());
    if (controller) {
      std::printf("%s", control.summary(*controller).c_str());
      writeJson(a.out + "_control.json", control.toJson(*controller));
      std::printf("wrote %s_control.json (each frame's decision and time)\n", a.out.c_str());
    }
    return 0;
  }
  FrameResult frame = renderer->render(rig, options);
  std::printf("  photon trace  %9.2f ms  (%zu photons stored)\n", frame.timings.photonTraceMs, frame.storedPhotons);
  std::printf("  map build     %9.2f ms  (%.1f MiB)\n", frame.timings.mapBuildMs, frame.mapBytes / 1048576.0);
  if (options.primary == PrimaryVisibility::Raster)
    std::printf("  raster pass   %9.2f ms  (both eyes' first hits by Vulkan; %.2f ms drawing, the rest copying)\n",
                frame.timings.primaryMs, frame.timings.primaryDrawMs);
  for (int e = 0; e < 2; ++e) {
    if (!options.eyes[e]) continue;
    std::printf("  %-5s eye     %9.2f ms  (eye rays %.2f, density %.2f", names[e], frame.timings.eyeMs[e],
                frame.timings.eyeRayMs[e], frame.timings.densityMs[e]);
    if (e == 1 && options.stereo == StereoMode::Scatter) std::printf(", scatter %.2f", frame.timings.scatterMs);
    std::printf(")\n");
  }
  if (options.stereo != StereoMode::Separate && options.foveation.mask) {
    std::printf("  stereo %s: right eye took %.1f%% of its %zu vertices from the left; right/left time %.2f\n",
                stereoModeName(options.stereo), 100.0 * double(frame.reusedPixels) / double(std::max<size_t>(frame.shadedSamples[1], 1)),
                frame.shadedSamples[1], frame.timings.eyeMs[0] > 0 ? frame.timings.eyeMs[1] / frame.timings.eyeMs[0] : 0.0);
  } else if (options.stereo != StereoMode::Separate) {
    double pixels = double(rig.width) * rig.height, surface = 0;
    for (float w : frame.eyes[1].inverseDepth) surface += w > 0.0f ? 1.0 : 0.0;
    std::printf("  stereo %s: right eye reused %.1f%% of its pixels (%.1f%% of those that see a surface) from the "
                "left; right/left time %.2f\n",
                stereoModeName(options.stereo), 100.0 * double(frame.reusedPixels) / pixels,
                surface > 0 ? 100.0 * double(frame.reusedPixels) / surface : 0.0,
                frame.timings.eyeMs[0] > 0 ? frame.timings.eyeMs[1] / frame.timings.eyeMs[0] : 0.0);
  }
  if (options.foveation.mask)
    std::printf("  foveated: %zu + %zu samples shaded (%.1fx fewer than the pixels), mask of %zu vertices\n",
                frame.shadedSamples[0], frame.shadedSamples[1],
                2.0 * rig.width * rig.height / double(std::max<size_t>(frame.shadedSamples[0] + frame.shadedSamples[1], 1)),
                mask.offsets.size());
  if (options.foveation.mask)
    std::printf("  gaze: left eye %.3f,%.3f, right eye %.3f,%.3f%s\n", frame.gaze[0][0], frame.gaze[0][1], frame.gaze[1][0],
                frame.gaze[1][1], options.foveation.verge ? " (fixating the left eye's point)" : "");
  if (frame.deviceBytes) std::printf("  GPU memory    %9.1f MiB\n", frame.deviceBytes / 1048576.0);
  std::printf("  total         %9.2f ms\n", frame.timings.totalMs());
  for (int e = 0; e < 2; ++e) {
    if (!options.eyes[e]) continue;
    for (const char* ext : {".png", ".exr"}) {
      std::string path = a.out + "_" + names[e] + ext;
      writeImage(frame.eyes[e].image, path, a.exposure);
      std::printf("wrote %s\n", path.c_str());
    }
  }
  if (frame.eyes[1].reusedFrom) {  // where the right eye took the left eye's shading (per pixel)
    const EyeResult& right = frame.eyes[1];
    Image mask(right.image.width, right.image.height);
    for (size_t i = 0; i < mask.pixels.size(); ++i)
      mask.pixels[i] = (*right.reusedFrom)[i] != kNotReused ? Vec3(1.0f) : (right.inverseDepth[i] > 0.0f ? Vec3(0.15f, 0, 0) : Vec3(0.0f));
    std::string path = a.out + "_right_reused.png";
    writeImage(mask, path, 1.0f);
    std::printf("wrote %s (white: reused from the left eye; red: shaded by the right eye; black: background)\n", path.c_str());
  }
  return 0;
}

struct ReferenceArgs {
  int passes = 256;
  double seconds = 0;  // 0: no time limit
  float alpha = 0.7f;
  std::string filter = "box";
  int frame = -1;  // a --trajectory frame's view
  std::string compare;  // EXR images PREFIX_left/right.exr to compare with the reference
};

// The converged reference of one view, written as linear EXR (and PNG) with a JSON of how far it
// got; optionally the error of other images against it.
int runReference(const RenderArgs& a, const ReferenceArgs& r) {
  if (r.passes < 1 || r.passes > kMaxReferencePasses)
    throw Error("--passes must be between 1 and " + std::to_string(kMaxReferencePasses) + ", got " + std::to_string(r.passes));
  if (!(r.seconds >= 0.0) || !std::isfinite(r.seconds)) throw Error("--seconds must be a non-negative number of seconds");
  if (!(r.alpha > 0.0f && r.alpha < 1.0f)) throw Error("--alpha must be between 0 and 1 (exclusive)");
  if (r.filter != "box" && r.filter != "centre") throw Error("--filter must be box or centre, got '" + r.filter + "'");
  if (r.frame >= 0 && a.trajectory.empty()) throw Error("--frame is for --trajectory");
  RenderArgs full = a;  // every pixel of each eye on its own: a settings file's foveation and TAA do not apply
  full.foveated = full.taa = false;
  full.mask.clear();
  full.taaBlend.clear();
  std::unique_ptr<RenderSetup> setup = setUpRender(full);
  StereoRig& rig = setup->rig;
  if (!setup->trajectory.empty()) {
    const int frame = std::max(r.frame, 0);
    if (size_t(frame) >= setup->trajectory.size())
      throw Error("--frame " + std::to_string(frame) + " is past the trajectory's " + std::to_string(setup->trajectory.size()) + " frames");
    rig.head = setup->trajectory[size_t(frame)].head;
  }
  ensureParentDirectory(a.out);
  std::unique_ptr<FrameRenderer> renderer = makeFrameRenderer(setup->backend, setup->scene);
  ReferenceSettings settings;
  settings.alpha = r.alpha;
  settings.boxFilter = r.filter == "box";
  const RenderOptions& options = setup->options;
  ProgressiveReference reference(*renderer, rig, options, settings);
  std::printf("reference of %s on %s (%s): %dx%d per eye, %u photons and %d spp per pass, radius %g shrinking with alpha %g, %s filter\n",
              setup->scene.name.c_str(), renderer->name().c_str(), renderer->deviceName().c_str(), rig.width, rig.height,
              options.photonCount(), options.gather.samplesPerPixel, options.gather.density.radius, r.alpha, r.filter.c_str());
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  const Eye reported = options.eyes[0] ? Eye::Left : Eye::Right;
  int nextReport = 1;
  while (reference.passes() < r.passes && (r.seconds == 0.0 || elapsed() < r.seconds)) {
    reference.addPass();
    if (reference.passes() == nextReport || reference.passes() == r.passes) {
      std::printf("  pass %6d: radius %.4g, %.1f s, estimated relMSE %.3g\n", reference.passes(),
                  reference.radiusOfPass(reference.passes() - 1), elapsed(), reference.estimatedRelMse(reported));
      std::fflush(stdout);
      nextReport *= 2;
    }
  }
  const char* names[2] = {"left", "right"};
  nlohmann::json j;
  j["scene"] = setup->scene.name;
  j["backend"] = renderer->name();
  j["device"] = renderer->deviceName();
  j["eye_size"] = {rig.width, rig.height};
  j["photons_per_pass"] = options.photonCount();
  j["spp_per_pass"] = options.gather.samplesPerPixel;
  j["first_radius"] = options.gather.density.radius;
  j["last_radius"] = reference.radiusOfPass(reference.passes() - 1);
  j["alpha"] = r.alpha;
  j["filter"] = r.filter;
  j["passes"] = reference.passes();
  j["seconds"] = elapsed();
  j["frame_ms"] = reference.frameMs();
  j["head"] = {{"position", {rig.head.position.x, rig.head.position.y, rig.head.position.z}},
               {"orientation", {rig.head.orientation.x, rig.head.orientation.y, rig.head.orientation.z, rig.head.orientation.w}}};
  for (int e = 0; e < 2; ++e) {
    if (!options.eyes[e]) continue;
    const Image image = reference.image(Eye(e));
    for (const char* ext : {".exr", ".png"}) writeImage(image, a.out + "_" + names[e] + ext, a.exposure);
    const double estimated = reference.estimatedRelMse(Eye(e));
    j[names[e]]["estimated_rel_mse"] = std::isfinite(estimated) ? nlohmann::json(estimated) : nlohmann::json(nullptr);
    std::printf("wrote %s_%s.exr/.png: %d passes, estimated relMSE %.3g (variance; the radius' bias falls faster)\n",
                a.out.c_str(), names[e], reference.passes(), estimated);
    if (!r.compare.empty()) {
      const std::string path = r.compare + "_" + names[e] + ".exr";
      const ReferenceError err = compareToReference(readExr(path), image, {}, a.exposure);
      j[names[e]]["compared"] = {{"file", path}, {"rel_mse", err.relMse}, {"psnr", err.psnr}, {"ssim", err.ssim},
                                 {"mean_ratio", err.meanRatio}};
      std::printf("  %s against it: relMSE %.4g, PSNR %.2f dB, SSIM %.4f, mean %.4f of the reference's\n", path.c_str(),
                  err.relMse, err.psnr, err.ssim, err.meanRatio);
    }
  }
  std::ofstream(a.out + ".json") << j.dump(2) << "\n";
  std::printf("wrote %s.json\n", a.out.c_str());
  return 0;
}

struct MaskArgs {
  std::string scene = "cornell";
  std::string eyeSize;
  std::string acuity = "linear";
  float mar0 = 1.0f / 48.0f, slope = 0.022f, margin = 5.0f;
  std::string out = "out/foveation.pvrmask";
};

int runMask(const MaskArgs& a) {
  Scene scene = loadScene(a.scene);
  StereoRig rig = scene.rig;
  if (!a.eyeSize.empty()) setEyeSize(rig, a.eyeSize);
  MaskParams params = maskParamsForRig(rig);
  if (a.acuity == "linear") params.acuity.kind = AcuityKind::LinearMar;
  else if (a.acuity == "geisler-perry") params.acuity.kind = AcuityKind::GeislerPerry;
  else throw Error("--acuity must be linear or geisler-perry, got '" + a.acuity + "'");
  if (!(a.mar0 > 0.0f && a.mar0 < 10.0f)) throw Error("--mar0 must be between 0 and 10 degrees");
  if (!(a.slope >= 0.0f && a.slope < 1.0f)) throw Error("--slope must be between 0 and 1");
  if (!(a.margin >= 0.0f && a.margin <= 90.0f)) throw Error("--margin must be between 0 and 90 degrees");
  params.acuity.mar0Deg = a.mar0, params.acuity.marSlope = a.slope, params.acuity.gazeMarginDeg = a.margin;
  FoveationMask mask = generateFoveationMask(params);
  ensureParentDirectory(a.out);
  saveFoveationMask(mask, a.out);
  std::vector<uint8_t> used = verticesInUse(mask, rig.width / 2, rig.height / 2);
  size_t shaded = 0;
  for (uint8_t u : used) shaded += u;
  double pixels = double(rig.width) * rig.height;
  std::printf("mask for %dx%d per eye (%.4f tan/pixel), %s acuity, full density within %.1f deg (%d pixels) of the gaze\n",
              rig.width, rig.height, params.tanPerPixel, a.acuity.c_str(),
              eccentricityDeg(mask.fullDensityRadius, params.tanPerPixel), mask.fullDensityRadius);
  std::printf("  %zu vertices, %zu Delaunay triangles; with the gaze at the image centre %zu samples are shaded "
              "per eye: %.1fx fewer than the %.0f pixels\n",
              mask.offsets.size(), mask.triangleCount(), shaded, pixels / double(std::max<size_t>(shaded, 1)), pixels);
  std::printf("wrote %s\n", a.out.c_str());
  return 0;
}

}  // namespace

int runCli(int argc, char** argv, CliRun run) {
  const bool execute = run == CliRun::Execute;
  // CheckOnly: the options' conversion and checks for a default rig; nothing loaded or rendered.
  auto checkOnly = [](const RenderArgs& a) {
    StereoRig rig;
    optionsFromArgs(a, rig);
    return 0;
  };
  CLI::App app{"photonvr: real-time photon mapping for VR headsets (CUDA backend, and the CPU reference: Embree + TBB)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "photonvr 0.1.0");

  RenderArgs ra;
  CLI::App* render = app.add_subcommand("render", "Render a stereo pair of a scene to PNG (sRGB) and EXR (linear)");
  render->footer(
      "Scenes: a built-in name (cornell, cornell-caustics, cornell-dense), a JSON scene file (docs/scene-format.md), or a mesh file\n"
      "(.gltf, .glb, .obj+.mtl, .3ds via assimp). Materials: glTF metallic-roughness (GGX metals, glossy and rough\n"
      "dielectrics, transmission / ior, base colour, metallic-roughness, normal, emissive and occlusion textures),\n"
      "OBJ/MTL Kd, Ks/Ns (glossy), mirrors (illum 3) and glass (illum 4-9), alpha MASK / map_d cut-outs, bump maps;\n"
      "point, spot and directional lights (KHR_lights_punctual) and a sky (JSON scenes).\n"
      "Defaults render the Cornell box at 1440x1600 per eye with 256x256 photons in a few seconds on 2 cores.");
  addImageCommandOptions(*render, ra, "Samples per pixel");
  addBudgetOptions(*render, ra);
  render->add_flag("--foveated", ra.foveated,
                   "Foveated: shade only a foveation mask's vertices around the gaze and reconstruct");
  render->add_option("--mask", ra.mask, "Foveation mask file from `photonvr mask` (default: made for the rig at start)");
  render->add_option("--gaze", ra.gaze, "Left eye's gaze point X,Y as fractions of the image (0.5,0.5 = centre); the right eye fixates the same surface point")
      ->capture_default_str();
  render->add_option("--trajectory", ra.trajectory,
                     "Render one frame per line of FILE: 'px py pz qx qy qz qw gx gy' (head pose; gaze as image "
                     "fractions, used with --foveated), or 11 numbers with a gaze per eye; '#' comments");
  render->add_flag("--taa", ra.taa,
                   "Temporal anti-aliasing across --trajectory frames: reprojection by depth and head motion, "
                   "neighbourhood clamping, reset on disocclusion");
  render->add_option("--taa-blend", ra.taaBlend, "Weight of the current frame under --taa, in (0, 1] (default 0.1)");
  addDenoiseOptions(*render, ra);
  render->add_option("--out", ra.out, "Output prefix: writes PREFIX_left.png/.exr and PREFIX_right.png/.exr")
      ->capture_default_str();

  render->add_option("--acuity", ra.acuity, "Acuity model of the mask made under --foveated: linear | geisler-perry")
      ->capture_default_str();
  render->add_option("--settings", ra.settings,
                     "Settings file (JSON, written by `photonvr view` with F12): options, head pose and gaze; flags given here win");

  RenderArgs referenceArgs;
  ReferenceArgs rfa;
  referenceArgs.out = "out/reference";
  referenceArgs.photons = "1024x1024";
  referenceArgs.spp = 4;
  referenceArgs.shadowRays = 0;
  CLI::App* referenceCmd = app.add_subcommand(
      "reference", "Render one view to convergence: progressive photon mapping (Knaus-Zwicker: passes with a shrinking "
                   "radius, averaged) with many samples per pixel; linear EXR, PNG and a JSON of the passes and the estimated error");
  addImageCommandOptions(*referenceCmd, referenceArgs, "Samples per pixel per pass");
  referenceCmd->add_option("--trajectory", referenceArgs.trajectory, "Trajectory file whose --frame gives the view");
  referenceCmd->add_option("--frame", rfa.frame, "The trajectory's frame (from 0) to render");
  referenceCmd->add_option("--settings", referenceArgs.settings, "Settings file (JSON) from `photonvr view`: options and the head pose");
  referenceCmd->add_option("--passes", rfa.passes, "Passes (independent frames) to average")->capture_default_str();
  referenceCmd->add_option("--seconds", rfa.seconds, "Stop after this many seconds even if passes remain (0: no limit)")
      ->capture_default_str();
  referenceCmd->add_option("--alpha", rfa.alpha, "Radius reduction: r_{i+1}^2 = r_i^2 (i + alpha) / (i + 1)")->capture_default_str();
  referenceCmd->add_option("--filter", rfa.filter, "Pixel filter: box (samples over the pixel) | centre (as the real-time image)")
      ->capture_default_str();
  referenceCmd->add_option("--compare", rfa.compare, "Prefix of images PREFIX_left/right.exr to compare against the reference");
  referenceCmd->add_option("--out", referenceArgs.out, "Output prefix: PREFIX_left/right.exr/.png and PREFIX.json")->capture_default_str();

  // xr and view: the same rendering options, and the loop's.
  RenderArgs xa, va;
  LoopCommandArgs xl, vl;
  CLI::App* xr = app.add_subcommand(
      "xr", "Run on an OpenXR headset (any runtime: SteamVR, Monado, Meta's; XR_KHR_vulkan_enable2), or --offscreen without one; "
            "writes per-frame statistics (p50/p99/max) as JSON");
  CLI::App* view = app.add_subcommand(
      "view", "Interactive desktop viewer (GLFW + Dear ImGui on Vulkan): both eyes, mouse-look, WASD, gaze under the cursor, "
              "every option live; F12 writes a screenshot and a settings file");
  for (auto [cmd, a] : {std::pair{xr, &xa}, std::pair{view, &va}}) {
    cmd->add_option("scene", a->scene, "Built-in scene name or scene/mesh file")->capture_default_str();
    addRenderOptions(*cmd, *a);
    addBudgetOptions(*cmd, *a);
    cmd->add_option("--eye-size", a->eyeSize, cmd == xr ? "Per-eye size WxH (default: the runtime's recommended size)"
                                                        : "Per-eye size WxH (default: 640x712)");
    cmd->add_option("--ipd", a->ipd, "Interpupillary distance in metres (view, --offscreen; a headset reports its own)");
    cmd->add_option("--spp", a->spp, "Samples per pixel")->capture_default_str();
    cmd->add_option("--specular-depth", a->specularDepth, "Mirror/glass bounces followed from the eye")->capture_default_str();
    cmd->add_option("--exposure", a->exposure, "Scale applied before display encoding")->capture_default_str();
    cmd->add_flag("--foveated", a->foveated, "Foveated rendering around the gaze");
    cmd->add_option("--acuity", a->acuity, "Acuity model of the foveation mask: linear | geisler-perry")->capture_default_str();
    cmd->add_option("--mask", a->mask, "Foveation mask file from `photonvr mask` (default: made for the eye size)");
    cmd->add_option("--shading", a->shading, "full | photons (the photon map alone)")->capture_default_str();
    cmd->add_option("--gaze", a->gaze, "Gaze X,Y (image fractions) when no eye tracker gives one")->capture_default_str();
    cmd->add_flag("--taa", a->taa, "Temporal anti-aliasing across the loop's frames");
    cmd->add_option("--taa-blend", a->taaBlend, "Weight of the current frame under --taa, in (0, 1]");
    addDenoiseOptions(*cmd, *a);
    cmd->add_option("--settings", a->settings, "Settings file (JSON) from `photonvr view`; flags given here win");
  }
  xr->add_option("--frames", xl.frames, "Frames to render, then end the session cleanly (0: until the runtime ends it or Ctrl-C)")
      ->capture_default_str();
  xr->add_option("--warmup", xl.warmup, "Frames rendered before the statistics start")->capture_default_str();
  xr->add_option("--stats", xl.stats, "Per-frame statistics as JSON (written on exit)")->capture_default_str();
  xr->add_flag("--offscreen", xl.offscreen, "No runtime: the same loop with views from --trajectory (or the scene's) in display slots");
  xr->add_option("--trajectory", xa.trajectory, "Offscreen: head poses and gaze, one frame per line (cycled)");
  xr->add_option("--handover", xl.handOver, "Offscreen: vulkan (hand the eyes to Vulkan images, timed) | none")->capture_default_str();
  xr->add_option("--refresh", xl.refreshHz, "Offscreen: display refresh rate in Hz (a frame later than its slot misses)")
      ->capture_default_str();
  xr->add_option("--cuda-copy", xl.cudaCopy,
                 "CUDA hand-over into the swapchain: buffer (a shared buffer, buffer-to-image copy) | image (a shared image, "
                 "image-to-image copy)")
      ->capture_default_str();
  xr->add_flag("--paced", xl.paced, "Offscreen: wait for each display slot as vsync would");
  xr->add_flag("--stdin-keys", xl.stdinKeys,
               "Read keys from standard input even when it is not a terminal (a terminal always gives keys): 1-5 put "
               "every material at raster, shadows, reflections, gi or path, e the next level, 0 the scene's own");
  xr->add_flag("--stage", xl.stage, "STAGE reference space (floor origin) instead of LOCAL (the head at start)");
  xr->add_flag("!--no-depth", xl.depthLayer, "Do not submit a depth layer");
  xr->add_option("--near", xl.nearZ, "Metres at depth 1 of the depth layer (reversed Z, infinite far)")->capture_default_str();
  xr->add_option("--ready-timeout", xl.readyTimeout, "Seconds the session may take to become READY")->capture_default_str();
  view->add_option("--frames", vl.frames, "Frames to show, then close (0: until the window is closed)")->capture_default_str();
  view->add_option("--screenshot", vl.screenshot, "Prefix of what F12 writes: PREFIX_left/right.png, PREFIX.json, PREFIX_window.png")
      ->capture_default_str();
  view->add_option("--keys", vl.keys, "Scripted key presses FRAME:KEY,... (e.g. 3:F12,5:Escape)");
  view->add_flag("--no-panel", vl.noPanel, "No options panel");

  RenderArgs sa;
  SoakArgs soakArgs;
  std::string reloadScenes;
  CLI::App* soak = app.add_subcommand(
      "soak", "Run the frame loop for many frames while every option cycles and the scene reloads; checks that no pixel is "
              "ever non-finite and that host memory, GPU memory and file descriptors stay flat (docs/reliability.md)");
  soak->add_option("scene", sa.scene, "Built-in scene name or scene/mesh file")->capture_default_str();
  addRenderOptions(*soak, sa);
  soak->add_option("--eye-size", sa.eyeSize, "Per-eye size WxH (default: 1440x1600)");
  soak->add_option("--trajectory", sa.trajectory, "Head poses and gaze, one frame per line (cycled; default: a sway)");
  soak->add_option("--frames", soakArgs.frames, "Frames to render (at least three cycles of the options)")->capture_default_str();
  soak->add_option("--change-every", soakArgs.changeEvery, "Frames between option changes (10 states: a cycle of 10x this)")
      ->capture_default_str();
  soak->add_option("--reload-every", soakArgs.reloadEvery, "Frames between scene reloads, a multiple of the cycle (0: each cycle)")
      ->capture_default_str();
  soak->add_option("--reload-scenes", reloadScenes, "Comma-separated scenes the reloads cycle through (default: the scene again)");
  soak->add_option("--json", soakArgs.json, "Where to write the samples and checks")->capture_default_str();
  soak->add_option("--max-rss-growth", soakArgs.maxRssGrowthMiB, "Allowed resident-set growth after warm-up, MiB")->capture_default_str();
  soak->add_option("--max-p99-ratio", soakArgs.maxP99Ratio, "Fail if the last cycle's p99 over the first's exceeds this (0: report only)")
      ->capture_default_str();

  MapBenchArgs ba;
  FrameBenchArgs fa;
  CLI::App* bench = app.add_subcommand(
      "bench", "Benchmarks that check their own results: the paper's Tables 1-4 as whole stereo frames (tables), "
               "Table 5, binocular reuse (stereo), "
               "CUDA ray throughput (rays), GPU hash-grid build (grid), CPU photon-map queries (maps)");
  bench->add_option("scene", ba.scene, "Scene for the tables, grid and maps suites")->capture_default_str();
  bench->add_option("--suite", fa.suite,
                    "tables | rays | grid | stereo | foveation | scenes (textured scenes, full shading) | quality (raw, "
                    "TAA and denoised frames against converged references, moving and still head) | effects (Ray-VR's "
                    "experiments: mono / stereo, rays / raster pre-pass, effect levels on all and on groups) | controller (the "
                    "budget controller on walks, against fixed settings) | all (tables, "
                    "stereo, rays, grid) | maps (CPU map queries)")
      ->capture_default_str();
  bench->add_option("--stereo", fa.stereo, "Table 5's columns: separate, scatter, gather (stereo suite)")
      ->capture_default_str();
  bench->add_option("--stereo-scenes", fa.stereoScenes,
                    "Scenes of the stereo suite: Table 5 on the first, one row on each other")
      ->capture_default_str();
  bench->add_option("--backend", fa.backend, "Backend of the tables suite: cpu | cuda | auto")->capture_default_str();
  bench->add_option("--tables", fa.tables, "Paper tables to run (tables suite)")->capture_default_str();
  bench->add_option("--frames", fa.frames,
                    "Timed frames per cell (tables, stereo, foveation): mean, p50, p99 and max are reported")
      ->capture_default_str();
  bench->add_option("--warmup", fa.warmup, "Warm-up frames per cell (tables suite)")->capture_default_str();
  bench->add_option("--eye-size", fa.eyeSize, "Per-eye resolution WxH (default: the scene's rig, 1440x1600)");
  bench->add_option("--rays-scenes", fa.raysScene, "Scenes of the rays suite")->capture_default_str();
  bench->add_option("--scenes", fa.scenes, "Scenes of the scenes suite (absent meshes are skipped)")->capture_default_str();
  bench->add_option("--scene-radius", fa.sceneRadius, "Search radius of the scenes suite, scene units")->capture_default_str();
  bench->add_option("--reference-passes", fa.referencePasses,
                    "Passes of the tables, scenes and quality suites' converged references (1024x1024 photons each)")
      ->capture_default_str();
  bench->add_option("--quality-scenes", fa.qualityScenes, "Scenes of the quality suite (absent meshes are skipped)")
      ->capture_default_str();
  bench->add_option("--quality-variants", fa.qualityVariants,
                    "Quality suite: the variants to run, by name, separated by ';' (\"raw\", every ratio's base, always runs)");
  bench->add_flag("!--no-quality-still", fa.qualityStill,
                  "Quality suite: the moving head's rows alone, without the still head's 450 frames a variant");
  bench->add_option("--quality-images", fa.qualityImages,
                    "Quality suite: write PNGs (the left eye's central 480x480) of a sampled frame of each variant and its reference to PREFIX_*.png");
  bench->add_option("--effects-scenes", fa.effectsScenes, "Scenes of the effects suite (absent meshes are skipped)")
      ->capture_default_str();
  bench->add_option("--profile-out", fa.profileOut,
                    "Effects suite: calibrate the budget controller on each scene, writing PREFIX_<scene>.json; controller "
                    "suite: fit its quality model on each walk (from --profiles' costs) and write it there");
  bench->add_option("--walks", fa.walks, "Controller suite: SCENE=TRAJECTORY,... (scripts/walk_trajectory.py makes walks)");
  bench->add_option("--budgets", fa.budgets, "Controller suite: frame budgets in ms")->capture_default_str();
  bench->add_option("--profiles", fa.profiles, "Controller suite: use PREFIX_<scene>.json (from --profile-out) where it exists");
  bench->add_option("--error-every", fa.errorEvery, "Controller suite: a converged reference of every Nth frame's view")
      ->capture_default_str();
  bench->add_option("--fixed-stride", fa.fixedStride,
                    "Controller suite: the fixed settings render every Nth frame of the walk (N divides --error-every)")
      ->capture_default_str();
  bench->add_option("--photons", ba.photons, "Comma-separated photon grids (maps suite)")->capture_default_str();
  bench->add_option("--radii", ba.radii, "Comma-separated search radii (maps suite)")->capture_default_str();
  bench->add_option("--queries", ba.queries, "Query points: eye hit points on a WxH grid of the left eye (maps suite)")
      ->capture_default_str();
  bench->add_option("--k", ba.k, "Photons per kNN query")->capture_default_str();
  bench->add_option("--repeats", ba.repeats, "Timed repetitions (maps suite): the minimum, and mean / p50 / p99 / max")
      ->capture_default_str();
  bench->add_option("--json", ba.json, "Also write the results as JSON to this file");

  MaskArgs ma;
  CLI::App* maskCmd = app.add_subcommand(
      "mask", "Make a foveation sampling mask (acuity-driven samples, Delaunay-triangulated by CGAL) for a scene's headset rig");
  maskCmd->add_option("scene", ma.scene, "Scene whose rig (eye size, FOV) the mask is for")->capture_default_str();
  maskCmd->add_option("--eye-size", ma.eyeSize, "Per-eye resolution WxH (default: the scene's rig, 1440x1600)");
  maskCmd->add_option("--acuity", ma.acuity, "linear (MAR = omega0 + m e, Guenter et al. 2012) | geisler-perry")
      ->capture_default_str();
  maskCmd->add_option("--mar0", ma.mar0, "omega0: MAR at the fovea, degrees")->capture_default_str();
  maskCmd->add_option("--slope", ma.slope, "m: MAR growth, degrees per degree of eccentricity")->capture_default_str();
  maskCmd->add_option("--margin", ma.margin, "Full density this many degrees around the gaze (eye-tracking error)")
      ->capture_default_str();
  maskCmd->add_option("--out", ma.out, "Mask file to write")->capture_default_str();

  try {
    app.parse(argc, argv);
    faultPlan();  // a malformed PVR_INJECT_FAULT is refused before anything runs
    if (maskCmd->parsed()) return execute ? runMask(ma) : 0;
    if (referenceCmd->parsed()) {
      if (!referenceArgs.settings.empty()) applySettings(referenceArgs.settings, referenceArgs, *referenceCmd);
      return execute ? runReference(referenceArgs, rfa) : checkOnly(referenceArgs);
    }
    if (render->parsed()) {
      if (!ra.settings.empty()) applySettings(ra.settings, ra, *render);
      return execute ? runRender(ra) : checkOnly(ra);
    }
    for (auto [cmd, a, l] : {std::tuple{xr, &xa, &xl}, std::tuple{view, &va, &vl}}) {
      if (!cmd->parsed()) continue;
      if (!a->settings.empty()) applySettings(a->settings, *a, *cmd);
      if (cmd == view && a->eyeSize.empty()) a->eyeSize = "640x712";
      // xr: the runtime's recommended size unless --eye-size is on this command line (a settings
      // file from the viewer holds the viewer's size).
      l->eyeSizeGiven = cmd == xr ? cmd->count("--eye-size") > 0 : !a->eyeSize.empty();
      l->exposure = a->exposure;
      l->sceneName = a->scene;
      l->acuity = a->acuity;
      l->budget = a->budget;
      l->controllerProfile = a->controllerProfile;
      if (l->cudaCopy != "buffer" && l->cudaCopy != "image") throw Error("--cuda-copy must be buffer or image, got '" + l->cudaCopy + "'");
      if (!(l->nearZ > 0.0f) || !std::isfinite(l->nearZ)) throw Error("--near must be a positive number of metres");
      if (!(l->readyTimeout > 0.0) || !std::isfinite(l->readyTimeout)) throw Error("--ready-timeout must be a positive number of seconds");
      if (!execute) return checkOnly(*a);
      std::unique_ptr<RenderSetup> setup = setUpRender(*a);
      LoopSetup ls;
      ls.backend = setup->backend;
      ls.scene = &setup->scene;
      ls.rig = setup->rig;
      ls.options = setup->options;
      ls.trajectory = setup->trajectory;
      return cmd == xr ? runXrCommand(*l, ls) : runViewCommand(*l, ls);
    }
    if (soak->parsed()) {
      soakArgs.scene = sa.scene;
      for (size_t start = 0; !reloadScenes.empty() && start <= reloadScenes.size();) {
        const size_t comma = std::min(reloadScenes.find(',', start), reloadScenes.size());
        if (comma == start) throw Error("--reload-scenes: an empty scene name in '" + reloadScenes + "'");
        soakArgs.reloadScenes.push_back(reloadScenes.substr(start, comma - start));
        start = comma + 1;
      }
      if (!execute) return checkOnly(sa);
      std::unique_ptr<RenderSetup> setup = setUpRender(sa);
      LoopSetup ls;
      ls.backend = setup->backend;
      ls.scene = &setup->scene;
      ls.rig = setup->rig;
      ls.options = setup->options;
      ls.trajectory = setup->trajectory;
      return runSoakCommand(soakArgs, ls);
    }
    if (bench->parsed()) {
      if (!execute) return 0;
      if (fa.suite == "maps") return runMapBench(ba);
      fa.scene = ba.scene;
      fa.k = ba.k;
      fa.json = ba.json;
      return runFrameBench(fa);
    }
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "photonvr: error: " << e.what() << " (see photonvr --help)\n";
    return 2;
  } catch (const OptionError& e) {
    std::cerr << "photonvr: error: " << describeForCli(e) << "\n";
    return 1;
  } catch (const Error& e) {
    std::cerr << "photonvr: error: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "photonvr: error: out of memory\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "photonvr: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace pvr
