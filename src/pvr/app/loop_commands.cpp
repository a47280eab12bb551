#include "pvr/app/loop_commands.h"

#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include <nlohmann/json.hpp>

#include "pvr/foveation/gaze.h"
#include "pvr/foveation/mask.h"
#include "pvr/loop/frame_loop.h"
#include "pvr/loop/loop_keys.h"
#include "pvr/loop/offscreen_presenter.h"
#include "pvr/util/error.h"
#include "pvr/viewer/viewer_presenter.h"
#include "pvr/vk/eye_transfer.h"
#include "pvr/vk/frame_source.h"
#include "pvr/xr/xr_presenter.h"
#ifdef PVR_HAVE_CUDA
#include "pvr/cuda/display_handover.h"
#endif

namespace pvr {
namespace {

std::atomic<bool> gStop{false};
extern "C" void onStopSignal(int) { gStop = true; }

void catchStopSignals() {
  gStop = false;
  std::signal(SIGINT, onStopSignal);
  std::signal(SIGTERM, onStopSignal);
}

std::vector<ScriptedView> scriptedPath(const std::vector<TrajectoryFrame>& trajectory) {
  std::vector<ScriptedView> path;
  for (const TrajectoryFrame& t : trajectory) {
    ScriptedView v;
    v.head = t.head;
    copyGaze(t, v);
    path.push_back(v);
  }
  return path;
}

nlohmann::json describeRun(const Renderer& renderer, const LoopSetup& setup, const RenderOptions& o) {
  return {{"backend", renderer.backendName()},
          {"device", renderer.deviceName()},
          {"scene", setup.scene->name},
          {"eye_size", {renderer.rig().width, renderer.rig().height}},
          {"photons", uint64_t(o.photonsX) * o.photonsY},
          {"photon_grid", std::to_string(o.photonsX) + "x" + std::to_string(o.photonsY)},
          {"radius", o.gather.density.radius},
          {"stereo", stereoModeName(o.stereo)},
          {"kernel", densityKernelName(o.kernel)},
          {"density", densitySchemeName(o.density)},
          {"primary", primaryVisibilityName(o.primary)},
          {"effects", o.gather.overrideEffects ? effectLevelName(o.gather.effects) : "per material"},
          {"foveated", o.foveation.mask != nullptr},
          {"taa", o.temporal.enabled},
          {"denoise", o.denoise.enabled}};
}

// A mask for the rig's size when foveated and the size changed (the headset chose it).
void refitMask(RenderOptions& options, const StereoRig& rig, const StereoRig& madeFor, const std::string& acuity,
               std::optional<FoveationMask>& mask) {
  if (!options.foveation.mask || (rig.width == madeFor.width && rig.height == madeFor.height)) return;
  std::fprintf(stderr, "photonvr: note: foveation mask made for the headset's %dx%d eyes\n", rig.width, rig.height);
  MaskParams params = maskParamsForRig(rig);
  if (acuity == "geisler-perry") params.acuity.kind = AcuityKind::GeislerPerry;
  mask = generateFoveationMask(params);
  options.foveation.mask = &*mask;
}

}  // namespace

void writeJson(const std::string& path, const nlohmann::json& j) {
  std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code error;
  if (!parent.empty()) std::filesystem::create_directories(parent, error);
  std::ofstream out(path);
  if (!out) throw Error("cannot write '" + path + "'");
  out << j.dump(2) << "\n";
}

BudgetSpec parseBudget(const std::string& text) {
  BudgetSpec spec;
  if (text.empty()) return spec;
  if (text == "display") {
    spec.ms = 1000.0 / 90.0;
    spec.followsDisplay = true;
    return spec;
  }
  size_t used = 0;
  double ms = 0;
  try {
    ms = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !(ms > 0.0) || !std::isfinite(ms) || ms > 10000.0)
    throw Error("--budget-ms must be a positive number of milliseconds (at most 10000) or 'display', got '" + text + "'");
  spec.ms = ms;
  return spec;
}

std::unique_ptr<BudgetController> makeBudgetController(const BudgetSpec& budget, const std::string& profilePath, const Scene& scene,
                                                       const RenderOptions& options, const StereoRig& rig,
                                                       const std::string& acuity, std::optional<FoveationMask>& mask) {
  if (!budget.enabled()) return nullptr;
  const ControlProfile profile = profilePath.empty() ? ControlProfile::generic(scene.effectGroupNames())
                                                     : ControlProfile::load(profilePath, scene.effectGroupNames());
  const FoveationMask* fovea = options.foveation.mask;
  if (!fovea && options.density == DensityScheme::PerPixel) {
    MaskParams params = maskParamsForRig(rig);
    if (acuity == "geisler-perry") params.acuity.kind = AcuityKind::GeislerPerry;
    mask = generateFoveationMask(params);
    fovea = &*mask;
  }
  BudgetControllerParams params;
  params.budgetMs = budget.ms;
  params.followsDisplay = budget.followsDisplay;
  params.foveationAvailable = fovea != nullptr;
  return std::make_unique<BudgetController>(profile, params, options, fovea);
}

int runXrCommand(const LoopCommandArgs& args, const LoopSetup& setup) {
  catchStopSignals();
  Renderer renderer(*setup.scene, setup.backend);
  renderer.rig() = setup.rig;
  renderer.options() = setup.options;
  renderer.options().eyes[0] = renderer.options().eyes[1] = true;  // a headset shows both
  FrameLoopOptions lo;
  lo.maxFrames = args.frames;
  lo.warmupFrames = args.warmup;
  lo.stop = &gStop;
  std::optional<FoveationMask> mask;
  nlohmann::json run;
  FrameStats stats;
  // Keys change the effect levels while the loop runs: from a terminal, or piped with --stdin-keys.
  std::optional<TerminalKeys> keys;
  if (args.stdinKeys || TerminalKeys::standardInputIsTerminal()) {
    keys.emplace();
    std::printf("xr: keys 1-5 put every material at raster, shadows, reflections, gi or path; e the next level; "
                "0 the scene's own levels\n");
  }
  auto runLoop = [&](Presenter& presenter) {
    if (!keys) return FrameLoop(renderer, presenter).run(lo);
    KeyedPresenter keyed(presenter, *keys, "xr");
    return FrameLoop(renderer, keyed).run(lo);
  };
  if (args.offscreen) {
    std::unique_ptr<VulkanContext> vk;
    std::unique_ptr<EyeTransfer> transfer;
    VulkanImage colour[2], depth[2];
    std::vector<double> handOverGpu, handOverEncode, handOverCopy, handOverLatency;
    OffscreenOptions oo;
    oo.refreshHz = args.refreshHz;
    oo.paced = args.paced;
    if (args.handOver == "vulkan") {
      VulkanContextOptions vo;
#ifdef PVR_HAVE_CUDA
      if (renderer.backendName() == "cuda") vo.hasPreferredUuid = cuda::currentDeviceUuid(vo.preferredUuid);
#endif
      vk = std::make_unique<VulkanContext>(vo);
      EyeTransferOptions to;
      to.width = setup.rig.width, to.height = setup.rig.height;
      to.depth = args.depthLayer;
      to.nearZ = args.nearZ;
      to.exposure = args.exposure;
      to.path = renderer.backendName() == "cuda" && vk->canShareWithCuda() ? HandOverPath::CudaShared : HandOverPath::HostStaging;
      to.colourViaImage = args.cudaCopy == "image";
      transfer = std::make_unique<EyeTransfer>(*vk, to);
      for (int e = 0; e < 2; ++e) {
        colour[e] = makeImage(*vk, to.width, to.height, VK_FORMAT_R8G8B8A8_SRGB, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
        depth[e] = makeImage(*vk, to.width, to.height, VK_FORMAT_D32_SFLOAT, VK_IMAGE_USAGE_TRANSFER_DST_BIT);
        vk->runOnce([&](VkCommandBuffer cmd) {
          transitionImage(cmd, colour[e].image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
          transitionImage(cmd, depth[e].image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
        });
      }
      oo.deviceImages = to.path == HandOverPath::CudaShared;
      oo.handOver = [&](const PresentedFrame& f) {
        EyeSource sources[2];
        EyeTarget targets[2];
        for (int e = 0; e < 2; ++e) {
          sources[e] = eyeSourceOf(f, Eye(e));
          targets[e] = {colour[e].image, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, depth[e].image,
                        VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
        }
        auto start = LoopClock::now();
        transfer->handOver(sources, targets);
        HandOverTiming t = transfer->lastTiming();  // waits: the hand-over is timed end to end
        handOverLatency.push_back(std::chrono::duration<double, std::milli>(LoopClock::now() - start).count());
        double encode = f.onDevice ? t.encodeMs : t.hostEncodeMs;
        handOverEncode.push_back(encode);
        handOverCopy.push_back(t.copyMs);
        handOverGpu.push_back(encode + t.copyMs);
      };
      run["vulkan_device"] = vk->deviceName();
      run["handover"] = transfer->describe();
    } else if (args.handOver != "none") {
      throw Error("--handover must be vulkan or none, got '" + args.handOver + "'");
    } else {
      run["handover"] = "none";
    }
    OffscreenPresenter presenter(setup.rig, scriptedPath(setup.trajectory), oo);
    std::printf("xr offscreen: %s backend (%s), eyes %dx%d, %.0f Hz slots%s, hand-over %s\n", renderer.backendName().c_str(),
                renderer.deviceName().c_str(), setup.rig.width, setup.rig.height, args.refreshHz, args.paced ? " (paced)" : "",
                run["handover"].get<std::string>().c_str());
    std::optional<FoveationMask> controlMask;
    std::unique_ptr<BudgetController> controller = makeBudgetController(
        parseBudget(args.budget), args.controllerProfile, *setup.scene, renderer.options(), renderer.rig(), args.acuity, controlMask);
    lo.controller = controller.get();
    stats = runLoop(presenter);
    auto skipWarmup = [&](std::vector<double> v) {
      if (v.size() > args.warmup) v.erase(v.begin(), v.begin() + long(args.warmup));
      return latencyStats(v);
    };
    if (transfer) {
      run["handover_ms"] = skipWarmup(handOverGpu);
      run["handover_encode_ms"] = skipWarmup(handOverEncode);
      run["handover_copy_ms"] = skipWarmup(handOverCopy);
      run["handover_latency_ms"] = skipWarmup(handOverLatency);
      const char* names[3] = {"hand-over encode (kernel/host)", "hand-over copy (Vulkan queue)", "hand-over, start to copy done"};
      const std::vector<double>* series[3] = {&handOverEncode, &handOverCopy, &handOverLatency};
      for (int i = 0; i < 3; ++i) {
        LatencyStats h = skipWarmup(*series[i]);
        std::printf("  %-30s mean %8.3f  p50 %8.3f  p99 %8.3f  max %8.3f ms\n", names[i], h.mean, h.p50, h.p99, h.max);
      }
    }
    run["presenter"] = "offscreen";
    run["refresh_hz"] = args.refreshHz;
  } else {
    XrPresenterOptions xo;
    xo.eyeWidth = args.eyeSizeGiven ? setup.rig.width : 0;
    xo.eyeHeight = args.eyeSizeGiven ? setup.rig.height : 0;
    xo.depthLayer = args.depthLayer;
    xo.nearZ = args.nearZ;
    xo.stageSpace = args.stage;
    xo.sceneFromSpace = setup.rig.head;  // the reference space's origin is the scene's viewpoint
    copyGaze(setup.options.foveation, xo);
    xo.exposure = args.exposure;
    xo.gpuImages = renderer.backendName() == "cuda";
    xo.readyTimeoutSeconds = args.readyTimeout;
    xo.stop = &gStop;
    xo.colourViaImage = args.cudaCopy == "image";
    XrPresenter presenter(xo);
    const XrSessionInfo& info = presenter.info();
    renderer.rig().width = info.eyeWidth, renderer.rig().height = info.eyeHeight;
    refitMask(renderer.options(), renderer.rig(), setup.rig, args.acuity, mask);
    std::printf("xr: %s, system '%s', Vulkan device %s\n", info.runtime.c_str(), info.system.c_str(), info.vulkanDevice.c_str());
    std::printf("  eyes %dx%d (runtime recommends %dx%d, at most %dx%d), swapchain %s, depth layer %s, eye tracker %s\n",
                info.eyeWidth, info.eyeHeight, info.recommendedWidth, info.recommendedHeight, info.maxWidth, info.maxHeight,
                info.colourFormat.c_str(), info.depthLayer ? "on" : "off", info.eyeTracker ? "yes" : "no (gaze from --gaze)");
    std::printf("  %s backend (%s), hand-over %s, %s space\n", renderer.backendName().c_str(), renderer.deviceName().c_str(),
                info.handOver.c_str(), info.space.c_str());
    if (info.controllerProfiles)
      std::printf("  controllers: right select, A or trackpad: every material at the next effect level; right B,\n"
                  "  left select or trackpad: the scene's own levels\n");
    std::optional<FoveationMask> controlMask;
    std::unique_ptr<BudgetController> controller = makeBudgetController(
        parseBudget(args.budget), args.controllerProfile, *setup.scene, renderer.options(), renderer.rig(), args.acuity, controlMask);
    lo.controller = controller.get();
    stats = runLoop(presenter);
    run["presenter"] = "openxr";
    run["runtime"] = info.runtime;
    run["system"] = info.system;
    run["vulkan_device"] = info.vulkanDevice;
    run["swapchain_format"] = info.colourFormat;
    run["depth_layer"] = info.depthLayer;
    run["eye_tracker"] = info.eyeTracker;
    run["gaze_frames_tracked"] = presenter.gazeFramesTracked();
    run["controller_profiles"] = info.controllerProfiles;
    run["controller_presses"] = presenter.controllerPresses();
    run["handover"] = info.handOver;
    run["display_time_known"] = info.displayTimeKnown;
    run["focus_changes"] = presenter.lifecycle().focusChanges();
    run["final_state"] = sessionStateName(presenter.lifecycle().state());
  }
  nlohmann::json out = describeRun(renderer, setup, renderer.options());
  out.update(run);
  out["stats"] = stats.toJson();
  out["stopped_by_signal"] = gStop.load();
  std::printf("%s", stats.summary().c_str());
  if (!args.stats.empty()) {
    writeJson(args.stats, out);
    std::printf("wrote %s\n", args.stats.c_str());
  }
  return 0;
}

int runViewCommand(const LoopCommandArgs& args, const LoopSetup& setup) {
  catchStopSignals();
  const RenderOptions& o = setup.options;
  ViewerSettings vs;
  vs.photonsLog2 = std::clamp(int(std::lround(std::log2(std::max<double>(1.0, std::sqrt(double(o.photonsX) * o.photonsY))))), 4, 10);
  vs.radius = o.gather.density.radius;
  vs.map = o.map == PhotonMapKind::KdTree;
  vs.estimator = o.gather.density.estimator == Estimator::Knn;
  vs.k = o.gather.density.k;
  vs.clippedBoundary = o.gather.density.boundary == Boundary::Clipped;
  vs.kernel = int(o.kernel == DensityKernel::Single ? 0 : o.kernel == DensityKernel::Hybrid ? 1 : o.kernel == DensityKernel::SharedMemory ? 2 : 3);
  vs.stereo = o.stereo == StereoMode::Separate ? 0 : o.stereo == StereoMode::Scatter ? 1 : 2;
  vs.foveated = o.foveation.mask != nullptr;
  vs.acuity = args.acuity == "geisler-perry";
  vs.taa = o.temporal.enabled;
  vs.taaBlend = o.temporal.taa.blend;
  vs.denoise = o.denoise.enabled;
  vs.rasterPrimary = o.primary == PrimaryVisibility::Raster;
  vs.effects = o.gather.overrideEffects ? 1 + int(o.gather.effects) : 0;
  vs.exposure = args.exposure;
  vs.bothEyes = o.eyes[1];
  BackendKind kind = setup.backend;
  if (kind == BackendKind::Auto) kind = cudaBackendAvailable() ? BackendKind::Cuda : BackendKind::Cpu;
  vs.backend = kind == BackendKind::Cuda;
  ViewerOptions vo;
  vo.screenshotPrefix = args.screenshot;
  vo.script = parseKeyScript(args.keys);
  vo.panel = !args.noPanel;
  vo.cudaAvailable = cudaBackendAvailable();
  const std::string sceneName = args.sceneName;
  const StereoRig rig0 = setup.rig;
  vo.writeSettings = [&](const std::string& path, const ViewerSettings& s, const FrameRequest& r) {
    const char* kernels[] = {"single", "hybrid", "shared", "sorted"};
    const char* stereo[] = {"separate", "scatter", "gather"};
    char radius[32], gaze[64];
    std::snprintf(radius, sizeof radius, "%.9g", s.radius);
    std::snprintf(gaze, sizeof gaze, "%.9g,%.9g", r.gaze[0][0], r.gaze[0][1]);
    const Pose& h = r.rig.head;
    nlohmann::json j = {{"scene", sceneName},
                        {"backend", s.backend ? "cuda" : "cpu"},
                        {"photons", std::to_string(1 << s.photonsLog2) + "x" + std::to_string(1 << s.photonsLog2)},
                        {"radius", radius},
                        {"map", s.map ? "kdtree" : "hashgrid"},
                        {"estimator", s.estimator ? "knn" : "radius"},
                        {"k", s.k},
                        {"boundary", s.clippedBoundary ? "clipped" : "sphere"},
                        {"kernel", kernels[s.kernel]},
                        {"stereo", stereo[s.stereo]},
                        {"foveated", s.foveated},
                        {"acuity", s.acuity ? "geisler-perry" : "linear"},
                        {"taa", s.taa},
                        {"denoise", s.denoise},
                        {"primary", s.rasterPrimary ? "raster" : "rays"},
                        {"effects", s.effects > 0 ? effectLevelName(EffectLevel(s.effects - 1)) : ""},
                        {"exposure", s.exposure},
                        {"eye_size", std::to_string(rig0.width) + "x" + std::to_string(rig0.height)},
                        {"gaze", gaze},
                        {"head", {{"position", {h.position.x, h.position.y, h.position.z}},
                                  {"orientation", {h.orientation.x, h.orientation.y, h.orientation.z, h.orientation.w}}}}};
    if (s.taa) j["taa_blend"] = std::to_string(s.taaBlend);
    writeJson(path, j);
  };
  ViewerPresenter viewer(setup.rig, vs, vo);
  FrameLoopOptions lo;
  lo.maxFrames = args.frames;
  lo.stop = &gStop;
  RenderOptions current = setup.options;  // the panel's changes survive a change of backend
  for (;;) {
    Renderer renderer(*setup.scene, kind);
    renderer.rig() = setup.rig;
    renderer.options() = current;
    std::printf("view: %s backend (%s), eyes %dx%d\n", renderer.backendName().c_str(), renderer.deviceName().c_str(),
                setup.rig.width, setup.rig.height);
    std::optional<FoveationMask> controlMask;
    std::unique_ptr<BudgetController> controller = makeBudgetController(
        parseBudget(args.budget), args.controllerProfile, *setup.scene, current, renderer.rig(), args.acuity, controlMask);
    lo.controller = controller.get();
    FrameStats stats = FrameLoop(renderer, viewer).run(lo);
    std::printf("%s", stats.summary().c_str());
    if (!controller) current = renderer.options();  // a controller's are its own: the panel's stay as asked
    if (!viewer.backendChangeRequested()) break;
    viewer.clearBackendChange();
    kind = viewer.settings().backend ? BackendKind::Cuda : BackendKind::Cpu;
  }
  return 0;
}

}  // namespace pvr
