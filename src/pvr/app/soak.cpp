#include "pvr/app/soak.h"

#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>

#include "pvr/foveation/gaze.h"
#include "pvr/foveation/mask.h"
#include "pvr/image/image_compare.h"
#include "pvr/loop/frame_loop.h"
#include "pvr/loop/offscreen_presenter.h"
#include "pvr/util/error.h"
#include "pvr/util/latency_stats.h"
#include "pvr/vulkan/vulkan_context.h"

#if defined(__SANITIZE_ADDRESS__)
#define PVR_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PVR_ASAN 1
#endif
#endif
#ifdef PVR_ASAN
// The sanitizer runtime's count of live allocations (gcc ships no header for it; libasan has it).
extern "C" size_t __sanitizer_get_current_allocated_bytes();
#endif

namespace pvr {
namespace {

constexpr uint64_t kMaxSoakFrames = 100000000;

size_t residentBytes() {
  std::ifstream statm("/proc/self/statm");
  size_t pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * size_t(sysconf(_SC_PAGESIZE));
}

// Bytes the process's heap holds in live allocations (glibc, all arenas, mmapped chunks included):
// unlike the resident set it does not move with fragmentation or an allocator's high-water mark,
// so a leak shows as growth here and a new high-water mark does not.
size_t heapBytesInUse() {
#ifdef PVR_ASAN
  return __sanitizer_get_current_allocated_bytes();  // ASan's allocator: glibc's heap is not used
#else
  const struct mallinfo2 m = mallinfo2();
  return m.uordblks + m.hblkhd;
#endif
}

int openFileDescriptors() {
  std::error_code ec;
  int n = 0;
  for (std::filesystem::directory_iterator it("/proc/self/fd", ec), end; !ec && it != end; it.increment(ec)) ++n;
  return n;
}

double mib(double bytes) { return bytes / (1024.0 * 1024.0); }

// One option state of the cycle: applied to the options the user asked for.
struct SoakState {
  std::string name;
  std::function<void(RenderOptions&)> apply;
};

std::vector<SoakState> soakStates(const FoveationMask* mask, bool raster) {
  auto scalePhotons = [](RenderOptions& o, float s) {
    o.photonsX = std::max(16u, uint32_t(float(o.photonsX) * s));
    o.photonsY = std::max(16u, uint32_t(float(o.photonsY) * s));
  };
  std::vector<SoakState> states = {
      {"as asked", [](RenderOptions&) {}},
      {"photons / 4, sorted kernel", [=](RenderOptions& o) { scalePhotons(o, 0.5f), o.kernel = DensityKernel::CellSorted; }},
      {"photons x 4, shared kernel", [=](RenderOptions& o) { scalePhotons(o, 2.0f), o.kernel = DensityKernel::SharedMemory; }},
      {"radius x 0.7, stereo gather", [](RenderOptions& o) { o.gather.density.radius *= 0.7f, o.stereo = StereoMode::Gather; }},
      {"stereo scatter, TAA", [](RenderOptions& o) { o.stereo = StereoMode::Scatter, o.temporal.enabled = true; }},
      {"foveated, gather, verging", [=](RenderOptions& o) {
         o.foveation.mask = mask, o.foveation.verge = true, o.stereo = StereoMode::Gather;
       }},
      {"denoiser, TAA, rolling map of 4", [](RenderOptions& o) {
         o.denoise.enabled = true, o.temporal.enabled = true, o.photonBatches = 4;
       }},
      {"surface cache, radius x 1.4", [](RenderOptions& o) {
         o.density = DensityScheme::SurfaceCache, o.gather.density.radius *= 1.4f;
       }},
      {"everything at shadows (no photons)", [](RenderOptions& o) {
         o.gather.overrideEffects = true, o.gather.effects = EffectLevel::Shadows;
       }},
      {raster ? "raster pre-pass, reflections" : "reflections (no Vulkan: no raster pre-pass)", [=](RenderOptions& o) {
         if (raster) o.primary = PrimaryVisibility::Raster;
         o.gather.overrideEffects = true, o.gather.effects = EffectLevel::Reflections;
       }},
  };
  return states;
}

// The offscreen display of the soak: the head path cycled, every frame's images checked for
// non-finite values, the options of the cycle's state applied before each frame. On the GPU the
// check runs there (a readback of both eyes at 1440x1600 and a host scan cost 40 ms a frame);
// every kHostCopyEvery-th frame still takes the host copy, so that path stays in the soak.
class SoakPresenter : public Presenter {
 public:
  SoakPresenter(StereoRig rig, std::vector<ScriptedView> path, const std::vector<SoakState>& states, RenderOptions base,
                uint64_t changeEvery)
      : rig_(rig), path_(std::move(path)), states_(states), base_(std::move(base)), changeEvery_(changeEvery) {}
  std::string name() const override { return "soak"; }
  static constexpr uint64_t kHostCopyEvery = 97;  // prime: it falls at every point of the cycle
  FrameOutput output(const Renderer& renderer) const override {
    return renderer.deviceStream() && !hostCopyFrame(frame_) ? FrameOutput::DeviceBuffers : FrameOutput::HostImages;
  }
  // Frames that took the host copy on the GPU: their time is the readback's, kept out of the p99.
  static bool hostCopyFrame(uint64_t frame) { return frame % kHostCopyEvery == 0; }
  bool waitFrame(FrameRequest& request) override {
    if (stopped_) return false;
    request.rig = rig_;
    if (!path_.empty()) {
      const ScriptedView& v = path_[frame_ % path_.size()];
      request.rig.head = v.head;
      copyGaze(v, request);
    }
    request.shouldRender = true;
    request.deadline.reset();
    return true;
  }
  void adjustOptions(RenderOptions& options) override {
    options = base_;
    states_[size_t((frame_ / changeEvery_) % states_.size())].apply(options);
  }
  void present(const PresentedFrame& f) override {
    if (!f.result) return;
    uint64_t nonFinite = 0;
    if (f.onDevice) {
      uint64_t counts[2];
      deviceCheck_.nonFinitePixels(f.renderer, counts);
      nonFinite = counts[0] + counts[1];
    } else {
      for (const EyeResult& eye : f.result->eyes) nonFinite += nonFinitePixels(eye.image);
    }
    if (nonFinite && nonFinite_ == 0) firstNonFiniteFrame_ = frame_;
    nonFinite_ += nonFinite;
    if (f.onDevice) ++deviceChecked_;
    deviceBytes_ = f.result->deviceBytes;
    injectLeaks();
    ++frame_;
  }
  void requestStop() override { stopped_ = true; }
  // Test hooks, so that the soak's own checks are shown to fail on a leak:
  // PVR_SOAK_INJECT_LEAK=BYTES keeps BYTES of touched memory per frame, PVR_SOAK_INJECT_FD_LEAK=1
  // opens a file every 100 frames and never closes it.
  void injectLeaks() {
    static const size_t leakBytes = [] {
      const char* v = std::getenv("PVR_SOAK_INJECT_LEAK");
      return v ? size_t(std::strtoull(v, nullptr, 10)) : size_t(0);
    }();
    static const bool leakFds = std::getenv("PVR_SOAK_INJECT_FD_LEAK") != nullptr;
    if (leakBytes) leaked_.emplace_back(leakBytes, char(1));
    if (leakFds && frame_ % 100 == 0) leakedFiles_.emplace_back(std::fopen("/dev/null", "r"));
  }
  void resume() { stopped_ = false; }
  uint64_t frame() const { return frame_; }
  uint64_t nonFinite() const { return nonFinite_; }
  uint64_t deviceChecked() const { return deviceChecked_; }  ///< frames checked on the GPU
  uint64_t firstNonFiniteFrame() const { return firstNonFiniteFrame_; }
  size_t deviceBytes() const { return deviceBytes_; }

 private:
  StereoRig rig_;
  std::vector<ScriptedView> path_;
  const std::vector<SoakState>& states_;
  RenderOptions base_;
  uint64_t changeEvery_;
  uint64_t frame_ = 0, nonFinite_ = 0, firstNonFiniteFrame_ = 0, deviceChecked_ = 0;
  DeviceImageCheck deviceCheck_;
  size_t deviceBytes_ = 0;
  bool stopped_ = false;
  std::vector<std::vector<char>> leaked_;
  std::vector<std::FILE*> leakedFiles_;
};

// The head path: the trajectory's, or a sway of the scene's head (a turn of +-20 degrees and a
// step of +-10 cm over 4 s at 90 Hz), so that reprojection and reuse see motion.
std::vector<ScriptedView> soakPath(const LoopSetup& setup) {
  std::vector<ScriptedView> path;
  for (const TrajectoryFrame& t : setup.trajectory) {
    ScriptedView v;
    v.head = t.head;
    copyGaze(t, v);
    path.push_back(v);
  }
  if (!path.empty()) return path;
  const int frames = 360;
  const float scale = std::max(0.5f * length(setup.scene->bounds().extent()), 1e-3f) * 0.05f;
  for (int i = 0; i < frames; ++i) {
    const float phase = 2.0f * kPi * float(i) / float(frames);
    ScriptedView v;
    v.head.orientation = setup.rig.head.orientation * Quat::fromAxisAngle({0, 1, 0}, 0.35f * std::sin(phase));
    v.head.position = setup.rig.head.position + setup.rig.head.toWorldDir({scale * std::sin(2.0f * phase), 0, 0});
    v.gaze[0][0] = v.gaze[1][0] = 0.5f + 0.2f * std::sin(3.0f * phase);
    v.gaze[0][1] = v.gaze[1][1] = 0.5f + 0.1f * std::cos(phase);
    path.push_back(v);
  }
  return path;
}

struct Sample {
  uint64_t frame;
  size_t rss, heap;
  int fds;
  size_t gpuTracked, gpuUsed;
};

// Least-squares slope of y over x.
double slope(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = double(x.size());
  if (x.size() < 2) return 0.0;
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < x.size(); ++i) sx += x[i], sy += y[i], sxx += x[i] * x[i], sxy += x[i] * y[i];
  const double d = n * sxx - sx * sx;
  return d > 0 ? (n * sxy - sx * sy) / d : 0.0;
}

}  // namespace

int runSoakCommand(const SoakArgs& args, const LoopSetup& setup) {
  const uint64_t cycle = uint64_t(kSoakStates) * args.changeEvery;
  if (args.changeEvery < 1 || args.changeEvery > 1000000) throw Error("--change-every must be between 1 and 1000000 frames");
  if (args.frames > kMaxSoakFrames) throw Error("--frames: a soak runs at most " + std::to_string(kMaxSoakFrames) + " frames");
  if (args.frames < 3 * cycle)
    throw Error("--frames must be at least three cycles of the options (3 x " + std::to_string(kSoakStates) +
                " states x --change-every = " + std::to_string(3 * cycle) + "): the first is warm-up");
  const uint64_t reloadEvery = args.reloadEvery ? args.reloadEvery : cycle;
  if (reloadEvery % cycle != 0)
    throw Error("--reload-every must be a multiple of the options' cycle (" + std::to_string(cycle) +
                " frames), so that memory is sampled at the same point of each");
  if (!(args.maxRssGrowthMiB >= 0.0) || !std::isfinite(args.maxRssGrowthMiB))
    throw Error("--max-rss-growth must be a non-negative number of MiB");
  if (!(args.maxP99Ratio >= 0.0) || !std::isfinite(args.maxP99Ratio)) throw Error("--max-p99-ratio must be a non-negative number");
  // The warm-up is the first cycle and, with reloads, the first load of each scene the reloads
  // cycle through (each new scene brings its own buffer sizes and allocator high-water marks
  // once). Memory is compared between samples a round of reloads apart (the same scene at the
  // same point of the cycle): the run must hold such a pair after the warm-up.
  const uint64_t reloadScenes = args.reloadScenes.empty() ? 1 : args.reloadScenes.size();
  const uint64_t round = reloadEvery < args.frames ? reloadEvery * reloadScenes : cycle;
  const uint64_t lastFrame = args.frames / cycle * cycle;
  uint64_t warmup = cycle;
  if (reloadEvery < args.frames) warmup = std::max(warmup, reloadEvery * reloadScenes + cycle);
  if (warmup + round > lastFrame) warmup = cycle;  // too short a run for that: the first cycle
  if (warmup + round > lastFrame)
    throw Error("--frames: the memory checks compare samples a round of reloads apart (" + std::to_string(round) +
                " frames) after the warm-up (" + std::to_string(warmup) + "): at least " + std::to_string(warmup + round) +
                " frames");

  // The raster pre-pass state needs a Vulkan device.
  bool raster = true;
  try {
    VulkanContext probe{VulkanContextOptions{}};
  } catch (const Error& e) {
    raster = false;
    std::fprintf(stderr, "photonvr: soak: no raster pre-pass state (%s)\n", e.what());
  }
  const FoveationMask mask = generateFoveationMask(maskParamsForRig(setup.rig));
  const std::vector<SoakState> states = soakStates(setup.options.foveation.mask ? setup.options.foveation.mask : &mask, raster);
  RenderOptions base = setup.options;
  base.eyes[0] = base.eyes[1] = true;
  base.foveation.mask = nullptr;
  SoakPresenter presenter(setup.rig, soakPath(setup), states, base, args.changeEvery);

  const Scene* scene = setup.scene;
  std::unique_ptr<Scene> owned;
  auto makeRenderer = [&](const Scene& s) {
    auto r = std::make_unique<Renderer>(s, setup.backend);
    r->rig() = setup.rig;
    r->options() = base;
    return r;
  };
  std::unique_ptr<Renderer> renderer = makeRenderer(*scene);
  std::printf("soak: %s backend (%s), eyes %dx%d, %llu frames, %d option states of %llu frames (cycle %llu), reload every %llu\n",
              renderer->backendName().c_str(), renderer->deviceName().c_str(), setup.rig.width, setup.rig.height,
              (unsigned long long)args.frames, kSoakStates, (unsigned long long)args.changeEvery, (unsigned long long)cycle,
              (unsigned long long)reloadEvery);

  if (renderer->deviceStream())
    std::printf("soak: images checked on the GPU; every %lluth frame copies them to the host instead, its time left out of the p99\n",
                (unsigned long long)SoakPresenter::kHostCopyEvery);

  // Everything the soak keeps per frame or cycle is reserved here, so that its own bookkeeping
  // does not grow the heap it measures.
  const size_t cycles = size_t(args.frames / cycle) + 1;
  std::vector<double> cycleMs;
  cycleMs.reserve(cycle);
  std::vector<LatencyStats> windows;
  windows.reserve(cycles);
  std::vector<Sample> samples;
  samples.reserve(cycles);
  nlohmann::json reloads = nlohmann::json::array();
  int reloadsFailed = 0, reloadsDone = 0;
  while (presenter.frame() < args.frames) {
    const uint64_t start = presenter.frame();
    const uint64_t next = std::min(args.frames, (start / cycle + 1) * cycle);
    FrameLoopOptions lo;
    lo.maxFrames = next - start;
    presenter.resume();
    const FrameStats stats = FrameLoop(*renderer, presenter).run(lo);
    cycleMs.clear();
    const bool onGpu = renderer->deviceStream() != nullptr;
    for (size_t i = 0; i < stats.records().size(); ++i)
      if (!onGpu || !SoakPresenter::hostCopyFrame(start + i)) cycleMs.push_back(stats.records()[i].cpuMs);
    if (presenter.frame() != next) throw Error("soak: the loop ended early, at frame " + std::to_string(presenter.frame()));
    if (next % cycle != 0) break;
    samples.push_back({next, residentBytes(), heapBytesInUse(), openFileDescriptors(), presenter.deviceBytes(), gpuMemoryUsedBytes()});
    const Sample& s = samples.back();
    windows.push_back(latencyStats(cycleMs));
    const LatencyStats& t = windows.back();
    std::printf("soak: frames %llu-%llu: mean %.2f p99 %.2f ms; resident %.1f MiB, heap %.2f MiB, %d fds, GPU %.1f MiB held (%.1f MiB in use on the device)\n",
                (unsigned long long)(next - cycle), (unsigned long long)next, t.mean, t.p99, mib(double(s.rss)), mib(double(s.heap)), s.fds,
                mib(double(s.gpuTracked)), mib(double(s.gpuUsed)));
    std::fflush(stdout);
    if (next % reloadEvery == 0 && next < args.frames) {
      const std::string name = args.reloadScenes.empty() ? args.scene : args.reloadScenes[size_t(reloadsDone + reloadsFailed) % args.reloadScenes.size()];
      try {
        // The new scene and its renderer first: if either fails, the previous ones keep rendering.
        auto loaded = std::make_unique<Scene>(loadScene(name));
        auto fresh = makeRenderer(*loaded);
        renderer = std::move(fresh);
        owned = std::move(loaded);
        scene = owned.get();
        ++reloadsDone;
        reloads.push_back({{"frame", next}, {"scene", name}, {"ok", true}});
      } catch (const Error& e) {
        ++reloadsFailed;
        std::printf("soak: reload of '%s' at frame %llu failed: %s; the previous scene keeps rendering\n", name.c_str(),
                    (unsigned long long)next, e.what());
        reloads.push_back({{"frame", next}, {"scene", name}, {"ok", false}, {"error", e.what()}});
      }
    }
  }

  // Checks over the samples after the warm-up (each at the end of a cycle).
  std::vector<double> x, rss, heap;
  int fdsMin = 1 << 30, fdsMax = 0;
  size_t trackedMin = ~size_t(0), trackedMax = 0, usedMin = ~size_t(0), usedMax = 0;
  for (size_t i = 0; i < samples.size(); ++i) {
    const Sample& s = samples[i];
    if (s.frame < warmup) continue;
    x.push_back(double(s.frame));
    rss.push_back(double(s.rss));
    heap.push_back(double(s.heap));
    fdsMin = std::min(fdsMin, s.fds), fdsMax = std::max(fdsMax, s.fds);
    trackedMin = std::min(trackedMin, s.gpuTracked), trackedMax = std::max(trackedMax, s.gpuTracked);
    usedMin = std::min(usedMin, s.gpuUsed), usedMax = std::max(usedMax, s.gpuUsed);
  }
  const double rssSlope = slope(x, rss), heapSlope = slope(x, heap);  // bytes per frame, for the record
  // Growth from the first sample after the warm-up to the last, two samples at the same point of
  // the reloads' round (each scene has its own sizes, so a slope across them would see the
  // alternation): a leak grows it, a scene's size or one allocator high-water mark does not.
  // The argument checks made sure that such a first sample exists and is not the last.
  const Sample& lastSample = samples.back();
  auto samePhase = [&](uint64_t frame) { return frame <= lastSample.frame && (lastSample.frame - frame) % round == 0; };
  const Sample* firstSample = &lastSample;
  for (const Sample& s : samples)
    if (s.frame >= warmup && samePhase(s.frame)) {
      firstSample = &s;
      break;
    }
  const double rssGrowth = double(lastSample.rss) - double(firstSample->rss);
  const double heapGrowth = double(lastSample.heap) - double(firstSample->heap);
  const uint64_t span = lastSample.frame - firstSample->frame;
  // p99 of the first cycle after the warm-up cycle against the last, taking the first at the same
  // point of the reloads' round as the last (the same scene: scenes differ in cost).
  size_t firstWindow = windows.size() - 1;  // none: the last against itself, reported as not compared
  for (size_t w = 1; w + 1 < windows.size(); ++w)
    if (w * cycle >= warmup && samePhase((w + 1) * cycle)) {
      firstWindow = w;
      break;
    }
  const bool p99Compared = firstWindow + 1 < windows.size();
  const LatencyStats first = windows[firstWindow];
  const LatencyStats last = windows.back();
  const double p99Ratio = first.p99 > 0 ? last.p99 / first.p99 : 0.0;

  nlohmann::json checks = nlohmann::json::array();
  int failures = 0;
  auto check = [&](const std::string& what, bool ok, const std::string& measured) {
    checks.push_back({{"check", what}, {"ok", ok}, {"measured", measured}});
    std::printf("soak: %-58s %s (%s)\n", what.c_str(), ok ? "ok" : "FAILED", measured.c_str());
    failures += ok ? 0 : 1;
  };
  char buf[256];
  std::snprintf(buf, sizeof buf, "%llu non-finite pixels; %llu frames checked on the GPU, the rest on the host",
                (unsigned long long)presenter.nonFinite(), (unsigned long long)presenter.deviceChecked());
  check("no non-finite pixel in any frame", presenter.nonFinite() == 0, buf);
  std::snprintf(buf, sizeof buf, "%+.2f MiB from frame %llu to %llu (slope %.2f KiB per 1000 frames)", mib(rssGrowth),
                (unsigned long long)firstSample->frame, (unsigned long long)lastSample.frame, rssSlope * 1000.0 / 1024.0);
  check("resident memory flat after warm-up (growth <= " + std::to_string(args.maxRssGrowthMiB).substr(0, 4) + " MiB)",
        rssGrowth <= args.maxRssGrowthMiB * 1024.0 * 1024.0, buf);
  // A leak of 16 bytes a frame over 10,000 frames is 160 KB: live heap may grow by 1 MiB at most.
  std::snprintf(buf, sizeof buf, "%+.3f MiB from frame %llu to %llu, %.1f bytes a frame (slope %.3f KiB per 1000 frames)",
                mib(heapGrowth), (unsigned long long)firstSample->frame, (unsigned long long)lastSample.frame,
                span ? heapGrowth / double(span) : 0.0, heapSlope * 1000.0 / 1024.0);
  check("live heap flat after warm-up (growth <= 1 MiB)", heapGrowth <= 1024.0 * 1024.0, buf);
  std::snprintf(buf, sizeof buf, "%d .. %d", fdsMin, fdsMax);
  check("open file descriptors constant after warm-up", fdsMin == fdsMax, buf);
  // GPU memory: every sample after the warm-up at the first sample's point of the round (the same
  // scene at the same point of the options' cycle) against that first one, so that the scenes'
  // own sizes cancel and a slow leak adds up.
  double trackedChange = 0, usedChange = 0;
  for (const Sample& s : samples)
    if (s.frame > firstSample->frame && samePhase(s.frame)) {
      trackedChange = std::max(trackedChange, std::abs(double(s.gpuTracked) - double(firstSample->gpuTracked)));
      usedChange = std::max(usedChange, std::abs(double(s.gpuUsed) - double(firstSample->gpuUsed)));
    }
  std::snprintf(buf, sizeof buf, "%.3f .. %.3f MiB over all scenes; at most %.3f MiB from frame %llu's", mib(double(trackedMin)),
                mib(double(trackedMax)), mib(trackedChange), (unsigned long long)firstSample->frame);
  check("GPU memory held by the renderer constant after warm-up", trackedChange == 0.0, buf);
  std::snprintf(buf, sizeof buf, "%.1f .. %.1f MiB over all scenes; at most %.2f MiB from frame %llu's", mib(double(usedMin)),
                mib(double(usedMax)), mib(usedChange), (unsigned long long)firstSample->frame);
  check("GPU memory in use on the device flat after warm-up (within 2 MiB)", usedChange <= double(size_t(2) << 20), buf);
  std::snprintf(buf, sizeof buf, "p99 %.2f ms (frames %llu-%llu), %.2f ms (last %llu), ratio %.3f", first.p99,
                (unsigned long long)(firstWindow * cycle), (unsigned long long)((firstWindow + 1) * cycle), last.p99,
                (unsigned long long)cycle, p99Ratio);
  if (!p99Compared)
    std::printf("soak: p99 not compared: no cycle after the warm-up at the last one's point of the reloads' round\n");
  else if (args.maxP99Ratio > 0)
    check("p99 steady (last window over first <= " + std::to_string(args.maxP99Ratio).substr(0, 4) + ")", p99Ratio <= args.maxP99Ratio, buf);
  else
    std::printf("soak: p99 first / last window after warm-up: %s (not checked: --max-p99-ratio)\n", buf);

  nlohmann::json out;
  out["backend"] = renderer->backendName();
  out["device"] = renderer->deviceName();
  out["scene"] = args.scene;
  out["eye_size"] = {setup.rig.width, setup.rig.height};
  out["photon_grid"] = std::to_string(base.photonsX) + "x" + std::to_string(base.photonsY);
  out["radius"] = base.gather.density.radius;
  out["frames"] = args.frames;
  out["change_every"] = args.changeEvery;
  out["cycle_frames"] = cycle;
  nlohmann::json names = nlohmann::json::array();
  for (const SoakState& s : states) names.push_back(s.name);
  out["states"] = names;
  out["non_finite_pixels"] = presenter.nonFinite();
  out["frames_checked_on_gpu"] = presenter.deviceChecked();
  if (presenter.nonFinite()) out["first_non_finite_frame"] = presenter.firstNonFiniteFrame();
  nlohmann::json js = nlohmann::json::array();
  for (const Sample& s : samples)
    js.push_back({{"frame", s.frame}, {"resident_bytes", s.rss}, {"heap_bytes", s.heap}, {"fds", s.fds}, {"gpu_held_bytes", s.gpuTracked},
                  {"gpu_device_used_bytes", s.gpuUsed}});
  out["samples"] = js;
  out["warmup_frames"] = warmup;
  out["resident_slope_bytes_per_frame"] = rssSlope;
  out["heap_slope_bytes_per_frame"] = heapSlope;
  out["growth_from_frame"] = firstSample->frame;
  out["growth_to_frame"] = lastSample.frame;
  out["resident_growth_bytes"] = rssGrowth;
  out["heap_growth_bytes"] = heapGrowth;
  out["frame_ms_per_cycle"] = windows;
  out["p99_first_ms"] = first.p99;
  out["p99_last_ms"] = last.p99;
  out["reloads"] = reloads;
  out["reloads_failed"] = reloadsFailed;
  out["checks"] = checks;
  out["passed"] = failures == 0;
  if (!args.json.empty()) {
    writeJson(args.json, out);
    std::printf("wrote %s\n", args.json.c_str());
  }
  return failures == 0 ? 0 : 1;
}

}  // namespace pvr
