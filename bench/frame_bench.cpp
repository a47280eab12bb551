#include "frame_bench.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "pvr/app/options.h"
#include "pvr/cpu/cpu_backend.h"
#include "pvr/foveation/mask.h"
#include "pvr/image/image_compare.h"
#include "pvr/photon/kd_tree.h"
#include "pvr/reference/progressive_reference.h"
#include "pvr/render/renderer.h"
#include "pvr/scene/scene.h"
#include "bench_util.h"
#include "controller_bench.h"
#include "effects_bench.h"
#include "quality_bench.h"
#include "pvr/util/latency_stats.h"
#include "pvr/util/error.h"
#include "pvr/util/parallel_for.h"
#ifdef PVR_HAVE_CUDA
#include "gpu_ray_throughput.h"
#include "pvr/cuda/cuda_frame_backend.h"
#endif

namespace pvr {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// Rays a frame casts, counted on the CPU by the shared algorithm code over a counting Embree
// intersector: every backend casts the same rays (the GPU is checked against the CPU), so
// dividing by a backend's stage times gives its rays per second.
struct CountingIntersector {
  const EmbreeIntersector& inner;
  mutable std::atomic<uint64_t> closest{0}, shadow{0};
  bool intersect(const Ray& ray, float tMax, Hit& hit) const {
    closest.fetch_add(1, std::memory_order_relaxed);
    return inner.intersect(ray, tMax, hit);
  }
  bool occluded(const Ray& ray, float tMax) const {
    shadow.fetch_add(1, std::memory_order_relaxed);
    return inner.occluded(ray, tMax);
  }
};

// Photon paths traced on the CPU by the shared code: their segments (rays) and stored photons.
struct PhotonPaths {
  uint64_t rays = 0, stored = 0;
};
PhotonPaths countPhotonPaths(const SceneView& view, const EmbreeIntersector& intersector, const PhotonTraceParams& tp) {
  CountingIntersector counter{intersector};
  std::atomic<uint64_t> stored{0};
  parallelFor("count photon rays", tp.photonCount, 4096, [&](size_t begin, size_t end) {
    std::vector<Photon> buffer(size_t(tp.maxDepth));
    uint64_t count = 0;
    for (size_t i = begin; i < end; ++i) count += uint64_t(tracePhoton(view, counter, tp, uint32_t(i), buffer.data()));
    stored += count;
  });
  return {counter.closest + counter.shadow, stored.load()};
}


// One column of one of the paper's tables.
struct Variant {
  std::string name;
  PhotonMapKind map;
  Estimator estimator;
  DensityKernel kernel;
  DensityScheme density = DensityScheme::PerPixel;  ///< ours: SurfaceCache (not the same image as the paper's)
};

struct Row {
  uint32_t photons;  ///< per side of the emitted grid
  float radius;
  std::vector<double> paperMs;  ///< the paper's RTX 2060 SUPER figures, one per paper column
};

struct Table {
  int number;
  std::string title;
  std::vector<Variant> variants;  ///< the paper's columns, then ours
  std::vector<Row> rows;
  // Per-pixel columns compute the same image as column 0 (checked), e.g. single vs hybrid.
  bool sameImage;
};

std::vector<Table> paperTables() {
  const auto grid = PhotonMapKind::HashGrid, kd = PhotonMapKind::KdTree;
  const auto knn = Estimator::Knn, radius = Estimator::Radius;
  const auto hybrid = DensityKernel::Hybrid;
  const auto cache = DensityScheme::SurfaceCache;
  std::vector<Table> t;
  t.push_back({1, "kd-tree vs hash grid (kNN max-heap, hybrid kernel); ours: the surface cache",
               {{"kd-tree", kd, knn, hybrid}, {"hash grid", grid, knn, hybrid}, {"hash grid + cache (ours)", grid, knn, hybrid, cache}},
               {{512, 0.02f, {10.80, 6.15}}, {512, 0.05f, {112.30, 84.50}}, {512, 0.1f, {470.31, 567.70}},
                {256, 0.05f, {12.48, 7.05}}, {256, 0.1f, {67.91, 48.68}}, {256, 0.2f, {314.21, 419.63}},
                {128, 0.05f, {3.58, 3.03}}, {128, 0.1f, {8.17, 5.73}}, {128, 0.2f, {38.81, 27.16}}},
               true});
  t.push_back({2, "heap vs no heap (hash grid, hybrid kernel); ours: the surface cache",
               {{"heap (kNN)", grid, knn, hybrid}, {"no heap (radius)", grid, radius, hybrid},
                {"heap + cache (ours)", grid, knn, hybrid, cache}, {"no heap + cache (ours)", grid, radius, hybrid, cache}},
               {{512, 0.02f, {6.61, 3.27}}, {512, 0.05f, {84.87, 8.26}}, {512, 0.1f, {583.50, 23.16}},
                {256, 0.05f, {7.53, 3.50}}, {256, 0.1f, {49.30, 6.54}}, {256, 0.2f, {414.93, 20.16}}},
               false});
  t.push_back({3, "single vs hybrid kernel (hash grid, radius); ours: the surface cache",
               {{"single", grid, radius, DensityKernel::Single}, {"hybrid", grid, radius, hybrid},
                {"cache (ours)", grid, radius, hybrid, cache}},
               {{512, 0.05f, {7.59, 4.48}}, {512, 0.1f, {22.01, 10.46}}, {512, 0.2f, {77.92, 36.82}},
                {256, 0.05f, {3.47, 2.85}}, {256, 0.1f, {6.39, 4.12}}, {256, 0.2f, {20.04, 10.55}}},
               true});
  t.push_back({4, "without vs with shared memory (hash grid, radius, hybrid); ours: cell-sorted, the surface cache",
               {{"no shared memory", grid, radius, hybrid},
                {"shared memory (Alg. 1)", grid, radius, DensityKernel::SharedMemory},
                {"cell-sorted (ours)", grid, radius, DensityKernel::CellSorted},
                {"cache (ours)", grid, radius, hybrid, cache}},
               {{512, 0.05f, {4.63, 4.95}}, {512, 0.1f, {11.86, 10.57}}, {512, 0.2f, {34.76, 32.01}},
                {256, 0.05f, {2.82, 2.79}}, {256, 0.1f, {4.12, 4.25}}, {256, 0.2f, {10.52, 9.30}}},
               true});
  return t;
}

// The scene's rig, at --eye-size if given.
StereoRig benchRig(const Scene& scene, const FrameBenchArgs& args) {
  StereoRig rig = scene.rig;
  if (!args.eyeSize.empty()) setEyeSize(rig, args.eyeSize);
  return rig;
}

// Mean absolute difference relative to the mean (over RGB), and the fraction of pixels that
// differ by more than 5% of the mean.
struct ImageDiff {
  double relativeMad = 0, outlierFraction = 0;
};
ImageDiff compareImages(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height || a.pixels.empty()) throw Error("image sizes differ");
  double sum = 0, diff = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      sum += std::fabs(double(a.pixels[i][c]));
      diff += std::fabs(double(a.pixels[i][c]) - double(b.pixels[i][c]));
    }
  double mean = sum / (3.0 * a.pixels.size());
  size_t outliers = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    float d = 0;
    for (int c = 0; c < 3; ++c) d = std::max(d, std::fabs(a.pixels[i][c] - b.pixels[i][c]));
    if (d > 0.05 * mean) ++outliers;
  }
  return {mean > 0 ? diff / (3.0 * a.pixels.size()) / mean : 0.0, double(outliers) / double(a.pixels.size())};
}

// One value per timed frame for each stage of FrameResult::timings; eye rays, density,
// reconstruction and TAA summed over both eyes (as the tables print them), eye pass = both eyes.
struct StageSamples {
  std::vector<double> trace, build, rays, density, eye[2], eyePass, scatter, reconstruct, temporal;
  void add(const StageTimings& t) {
    trace.push_back(t.photonTraceMs);
    build.push_back(t.mapBuildMs);
    rays.push_back(t.eyeRayMs[0] + t.eyeRayMs[1]);
    density.push_back(t.densityMs[0] + t.densityMs[1]);
    eye[0].push_back(t.eyeMs[0]);
    eye[1].push_back(t.eyeMs[1]);
    eyePass.push_back(t.eyeMs[0] + t.eyeMs[1]);
    scatter.push_back(t.scatterMs);
    reconstruct.push_back(t.reconstructMs[0] + t.reconstructMs[1]);
    temporal.push_back(t.temporalMs[0] + t.temporalMs[1]);
  }
};

// The LatencyStats of each stage over a cell's timed frames.
struct StageStats {
  LatencyStats trace, build, rays, density, eye[2], eyePass, scatter, reconstruct, temporal;
  StageStats() = default;
  explicit StageStats(const StageSamples& s)
      : trace(latencyStats(s.trace)), build(latencyStats(s.build)), rays(latencyStats(s.rays)),
        density(latencyStats(s.density)), eye{latencyStats(s.eye[0]), latencyStats(s.eye[1])},
        eyePass(latencyStats(s.eyePass)), scatter(latencyStats(s.scatter)),
        reconstruct(latencyStats(s.reconstruct)), temporal(latencyStats(s.temporal)) {}
  // {"photon_trace": {mean, p50, p99, max}, ...} for the stages that ran: those timed above 0 in
  // some frame (a stage that did not run, or that a backend does not time on its own, such as
  // density inside the CPU's fused eye pass, reads 0).
  nlohmann::json json() const {
    const std::pair<const char*, const LatencyStats*> named[] = {
        {"photon_trace", &trace}, {"map_build", &build}, {"eye_rays", &rays},   {"density", &density},
        {"left_eye", &eye[0]},    {"right_eye", &eye[1]}, {"eye_pass", &eyePass}, {"scatter", &scatter},
        {"reconstruct", &reconstruct}, {"temporal", &temporal}};
    nlohmann::json out = nlohmann::json::object();
    for (const auto& [name, stats] : named)
      if (stats->max > 0) out[name] = *stats;
    return out;
  }
};

struct CellResult {
  int frames = 0;      ///< timed frames
  LatencyStats frame;  ///< host wall time of the whole stereo frame
  StageStats stages;   ///< the backend's stage timings
  size_t stored = 0, deviceBytes = 0, mapBytes = 0, reusedPixels = 0;
  FrameResult last;  ///< a frame with images, for the checks
  // The JSON every timed cell carries: "frames", "frame" and "stages" (see StageStats::json).
  nlohmann::json latencyJson() const { return {{"frames", frames}, {"frame", frame}, {"stages", stages.json()}}; }
};

CellResult timeCell(FrameRenderer& renderer, const StereoRig& rig, const RenderOptions& o, int warmup, int frames) {
  CellResult r;
  for (int i = 0; i < warmup; ++i) renderer.render(rig, o, false);
  std::vector<double> frameMs;
  StageSamples stages;
  for (int i = 0; i < frames; ++i) {
    auto start = Clock::now();
    FrameResult f = renderer.render(rig, o, false);
    frameMs.push_back(msSince(start));
    stages.add(f.timings);
    r.reusedPixels = f.reusedPixels;
    r.stored = f.storedPhotons;
    r.deviceBytes = std::max(r.deviceBytes, f.deviceBytes);
    r.mapBytes = f.mapBytes;
  }
  r.frames = frames;
  r.frame = latencyStats(std::move(frameMs));
  r.stages = StageStats(stages);
  r.last = renderer.render(rig, o, true);
  return r;
}

RenderOptions tableOptions(const Row& row, const Variant& v, int k) {
  RenderOptions o;
  o.photonsX = o.photonsY = row.photons;
  o.map = v.map;
  o.kernel = v.kernel;
  o.density = v.density;
  o.gather.mode = ShadingMode::PhotonMapOnly;  // the paper's formulation
  o.gather.density.radius = row.radius;
  o.gather.density.estimator = v.estimator;
  o.gather.density.k = k;
  return o;
}

// The view's converged reference for the tables' error columns: the same view for every row
// (progressive photon mapping from r = 0.05, 1024x1024 photons a pass, pixel centres as the cells').
struct ViewReference {
  Image eyes[2];
  double estimatedRelMse[2] = {0, 0};
  int passes = 0;
};
ViewReference convergedReference(FrameRenderer& renderer, const StereoRig& rig, int passes) {
  RenderOptions ro;
  ro.photonsX = ro.photonsY = 1024;
  ro.gather.density.radius = 0.05f;
  ro.gather.punctualShadowRays = 0;  // no light-selection noise
  ro.gather.seed = 0x5eed;           // independent of the cells' numbers
  ReferenceSettings settings;
  settings.boxFilter = false;
  ProgressiveReference reference(renderer, rig, ro, settings);
  for (int i = 0; i < passes; ++i) reference.addPass();
  ViewReference v;
  for (int e = 0; e < 2; ++e) v.eyes[e] = reference.image(Eye(e)), v.estimatedRelMse[e] = reference.estimatedRelMse(Eye(e));
  v.passes = passes;
  return v;
}

// The mean over both eyes of a frame's relMSE against the reference.
double relMseOfFrame(const FrameResult& frame, const ViewReference& reference) {
  return 0.5 * (compareToReference(frame.eyes[0].image, reference.eyes[0]).relMse +
                compareToReference(frame.eyes[1].image, reference.eyes[1]).relMse);
}

int runTables(const FrameBenchArgs& args, const Scene& scene, FrameRenderer& renderer, const StereoRig& rig,
              nlohmann::json& json) {
  int failures = 0;
  std::vector<int> wanted;
  for (const std::string& t : splitList(args.tables)) {
    if (t != "1" && t != "2" && t != "3" && t != "4") throw Error("--tables takes numbers 1 to 4, got '" + t + "'");
    wanted.push_back(std::stoi(t));
  }
  if (args.referencePasses < 2 || args.referencePasses > kMaxReferencePasses)
    throw Error("--reference-passes must be between 2 and " + std::to_string(kMaxReferencePasses));
  const ViewReference reference = convergedReference(renderer, rig, args.referencePasses);
  std::printf("\nPaper tables on %s (%s backend): scene %s, both eyes %dx%d, photon-map-only shading (the paper's), "
              "kNN k=%d, %d timed frames per cell after %d warm-up frames; surface cache cells of %g x the radius.\n"
              "Frame = wall time of one stereo frame (photon trace + map build + both eyes), synchronized; stages "
              "by CUDA events. Times: mean / p99 over the timed frames (p99 by nearest rank: the max under 100 "
              "frames). Paper = RTX 2060 SUPER, one view, mean. Speed-up = the paper's fastest cell of the row over "
              "our fastest (mean; p99 in brackets). relMSE = mean of both eyes' against the view's converged "
              "reference (%d progressive passes of 1024x1024 photons from r = 0.05, pixel centres; its estimated "
              "relMSE %.1e / %.1e); each cache column's must be within 5%% of (or below) its per-pixel column's.\n",
              renderer.deviceName().c_str(), renderer.name().c_str(), scene.name.c_str(), rig.width, rig.height, args.k,
              args.frames, args.warmup, double(kDefaultCacheCellFraction), reference.passes,
              reference.estimatedRelMse[0], reference.estimatedRelMse[1]);
  for (const Table& table : paperTables()) {
    if (std::find(wanted.begin(), wanted.end(), table.number) == wanted.end()) continue;
    std::printf("\nTable %d: %s\n\n| photons | radius |", table.number, table.title.c_str());
    for (const Variant& v : table.variants) std::printf(" %s ms (mean / p99) |", v.name.c_str());
    for (size_t c = 0; c < 2; ++c) std::printf(" paper %s ms |", table.variants[c].name.c_str());
    std::printf(" speed-up | relMSE (columns in order) | check |\n|---|---|");
    for (size_t c = 0; c < table.variants.size() + 5; ++c) std::printf("---|");
    std::printf("\n");
    std::string details;
    for (const Row& row : table.rows) {
      std::vector<CellResult> cells;
      std::vector<double> relMse;
      for (const Variant& v : table.variants) {
        cells.push_back(timeCell(renderer, rig, tableOptions(row, v, args.k), args.warmup, args.frames));
        relMse.push_back(relMseOfFrame(cells.back().last, reference));
      }
      std::string check = "ok";
      double worst = 0;
      if (table.sameImage) {
        for (size_t c = 1; c < cells.size(); ++c) {
          if (table.variants[c].density != DensityScheme::PerPixel) continue;
          for (int e = 0; e < 2; ++e) {
            ImageDiff d = compareImages(cells[0].last.eyes[e].image, cells[c].last.eyes[e].image);
            worst = std::max(worst, d.relativeMad);
            if (d.relativeMad > 0.005 || d.outlierFraction > 0.002) check = "MISMATCH";
          }
        }
      }
      if (check != "ok") ++failures;
      // Each cache column against the per-pixel column of the same map and estimator.
      std::string errorCheck;
      std::vector<double> errorRatio(cells.size(), 0.0);
      for (size_t c = 0; c < cells.size(); ++c) {
        const Variant& v = table.variants[c];
        if (v.density == DensityScheme::PerPixel) continue;
        for (size_t p = 0; p < cells.size(); ++p) {
          const Variant& w = table.variants[p];
          if (w.density != DensityScheme::PerPixel || w.map != v.map || w.estimator != v.estimator) continue;
          errorRatio[c] = relMse[c] / std::max(relMse[p], 1e-30);
          break;
        }
        char text[96];
        std::snprintf(text, sizeof text, "%s%s x%.3f", errorCheck.empty() ? "" : ", ",
                      errorRatio[c] <= 1.05 ? "error" : "ERROR WORSE", errorRatio[c]);
        errorCheck += text;
        if (cells[c].last.cacheUnplaced > 0) errorCheck += " (some points had no cell)";
      }
      double bestOurs = 1e30, bestOursP99 = 1e30, bestPaper = 1e30;
      for (const CellResult& c : cells) bestOurs = std::min(bestOurs, c.frame.mean), bestOursP99 = std::min(bestOursP99, c.frame.p99);
      for (double p : row.paperMs) bestPaper = std::min(bestPaper, p);
      std::printf("| %ux%u | %g |", row.photons, row.photons, row.radius);
      for (const CellResult& c : cells) std::printf(" %s |", meanP99(c.frame, 2).c_str());
      for (double p : row.paperMs) std::printf(" %.2f |", p);
      std::printf(" x%.1f (x%.1f) |", bestPaper / bestOurs, bestPaper / bestOursP99);
      for (size_t c = 0; c < cells.size(); ++c) std::printf("%s%.4f", c ? " / " : " ", relMse[c]);
      std::printf(" |");
      if (table.sameImage) std::printf(" %s (%.1e)%s%s |\n", check.c_str(), worst, errorCheck.empty() ? "" : "; ", errorCheck.c_str());
      else std::printf(" %s |\n", errorCheck.empty() ? "n/a" : errorCheck.c_str());
      for (size_t c = 0; c < cells.size(); ++c) {
        const CellResult& r = cells[c];
        const bool cached = table.variants[c].density == DensityScheme::SurfaceCache;
        char line[1024];
        std::snprintf(line, sizeof line,
                      "| %ux%u | %g | %s | %.2f / %.2f / %.2f / %.2f | %s | %s | %s | %s | %zu | %.1f | %.1f | %.4f | %s |\n",
                      row.photons, row.photons, row.radius, table.variants[c].name.c_str(), r.frame.mean, r.frame.p50,
                      r.frame.p99, r.frame.max, meanP99(r.stages.trace, 3).c_str(), meanP99(r.stages.build, 3).c_str(),
                      meanP99(r.stages.rays, 2).c_str(), meanP99(r.stages.density, 2).c_str(), r.stored,
                      r.mapBytes / 1048576.0, r.deviceBytes / 1048576.0, relMse[c],
                      cached ? std::to_string(r.last.cacheCells).c_str() : "-");
        details += line;
        nlohmann::json cell = {
            {"table", table.number}, {"photons", row.photons * row.photons}, {"photons_grid", row.photons},
            {"radius", row.radius}, {"variant", table.variants[c].name},
            {"density", densitySchemeName(table.variants[c].density)}, {"frame_ms", r.frame.mean},
            {"trace_ms", r.stages.trace.mean}, {"build_ms", r.stages.build.mean}, {"eye_rays_ms", r.stages.rays.mean},
            {"density_ms", r.stages.density.mean}, {"stored_photons", r.stored}, {"map_bytes", r.mapBytes},
            {"device_bytes", r.deviceBytes}, {"rel_mse_vs_reference", relMse[c]},
            {"reference_passes", reference.passes},
            {"paper_ms", c < row.paperMs.size() ? nlohmann::json(row.paperMs[c]) : nlohmann::json()},
            {"check", table.sameImage && !cached ? check : "n/a"}};
        if (cached)
          cell.update({{"cache_cells", r.last.cacheCells}, {"cache_unplaced_points", r.last.cacheUnplaced},
                       {"cache_cell_fraction", kDefaultCacheCellFraction}, {"error_vs_per_pixel", errorRatio[c]},
                       {"error_check", errorRatio[c] <= 1.05 ? "ok" : "worse"}});
        cell.update(r.latencyJson());
        json.push_back(cell);
      }
      std::fflush(stdout);
    }
    std::printf("\nTable %d per stage (ms per stereo frame over %d timed frames; frame: mean / p50 / p99 / max, "
                "stages: mean / p99; eye rays and density summed over both eyes):\n\n"
                "| photons | radius | variant | frame (mean / p50 / p99 / max) | trace | build | eye rays | density | "
                "stored | map MiB | GPU MiB | relMSE | cache cells |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n%s",
                table.number, args.frames, details.c_str());
  }
  return failures;
}

// The paper's Table 5: both eyes shaded separately against the right eye reusing the left eye's
// shading. Quality: the right eye with reuse against the right eye rendered separately from the
// same photon map (photon tracing is deterministic), as displayed (sRGB).
int runStereo(const FrameBenchArgs& args, FrameRenderer& renderer, nlohmann::json& json) {
  std::vector<StereoMode> modes;
  for (const std::string& m : splitList(args.stereo)) modes.push_back(parseStereoMode(m));
  if (std::find(modes.begin(), modes.end(), StereoMode::Separate) == modes.end())
    modes.insert(modes.begin(), StereoMode::Separate);  // the baseline the others are compared with
  struct StereoRow {
    uint32_t photons;
    float radius;
  };
  const std::vector<StereoRow> paperRows = {{512, 0.05f}, {512, 0.1f}, {512, 0.2f},
                                            {256, 0.05f}, {256, 0.1f}, {256, 0.2f}};
  int failures = 0;
  std::vector<std::string> scenes = splitList(args.stereoScenes);
  for (size_t si = 0; si < scenes.size(); ++si) {
    Scene scene = loadScene(scenes[si]);
    StereoRig rig = benchRig(scene, args);
    std::unique_ptr<FrameRenderer> sceneRenderer;  // the caller's renderer is for args.scene
    FrameRenderer* r = &renderer;
    if (scenes[si] != args.scene) {
      sceneRenderer = makeFrameRenderer(renderer.name() == "cuda" ? BackendKind::Cuda : BackendKind::Cpu, scene);
      r = sceneRenderer.get();
    }
    std::vector<StereoRow> rows = si == 0 ? paperRows : std::vector<StereoRow>{paperRows[0]};
    std::printf("\nTable 5%s: separate eyes vs binocular reuse on %s (%s backend), scene %s, both eyes %dx%d, "
                "IPD %.0f mm, hash grid, radius estimate, hybrid kernel, photon-map-only shading, %d timed frames "
                "after %d warm-up.\nTimes: mean / p99 over the timed frames (p99 by nearest rank: the max under 100 "
                "frames). right/left = right eye's time (scatter included) over the left eye's; reused = share of "
                "right-eye pixels that took the left eye's shading (in brackets: of those that see a surface, not the "
                "background); PSNR and >1%% = right eye against its separate "
                "rendering from the same photon map, displayed (sRGB).\n\n| photons | radius |",
                si == 0 ? "" : " (other scenes)", r->deviceName().c_str(), r->name().c_str(), scene.name.c_str(),
                rig.width, rig.height, rig.ipd * 1000.0f, args.frames, args.warmup);
    for (StereoMode m : modes) std::printf(" %s ms (mean / p99) |", stereoModeName(m));
    std::printf("\n|---|---|");
    for (size_t c = 0; c < modes.size(); ++c) std::printf("---|");
    std::printf("\n");
    std::string details;
    for (const StereoRow& row : rows) {
      std::vector<CellResult> cells;
      for (StereoMode m : modes) {
        RenderOptions o;
        o.photonsX = o.photonsY = row.photons;
        o.gather.mode = ShadingMode::PhotonMapOnly;
        o.gather.density.radius = row.radius;
        o.gather.density.estimator = Estimator::Radius;
        o.kernel = DensityKernel::Hybrid;
        o.stereo = m;
        cells.push_back(timeCell(*r, rig, o, args.warmup, args.frames));
      }
      std::printf("| %ux%u | %g |", row.photons, row.photons, row.radius);
      for (const CellResult& c : cells) std::printf(" %s |", meanP99(c.frame, 2).c_str());
      std::printf("\n");
      const FrameResult& reference = cells[0].last;
      for (size_t c = 0; c < cells.size(); ++c) {
        const CellResult& cell = cells[c];
        ImageComparison q = compareDisplayed(cell.last.eyes[1].image, reference.eyes[1].image);
        // Self-check: reuse leaves the left eye alone and does not wreck the right one.
        bool leftSame = compareDisplayed(cell.last.eyes[0].image, reference.eyes[0].image).meanSquaredError == 0;
        bool ok = leftSame && (c == 0 || q.psnr >= 30.0);
        failures += ok ? 0 : 1;
        double reuse = double(cell.last.reusedPixels) / (double(rig.width) * rig.height);
        double surface = 0;  // right-eye pixels that see a surface (the rest is background)
        for (uint32_t prim : reference.eyes[1].firstPrim.value()) surface += prim != ~0u ? 1.0 : 0.0;
        double reuseOfSurface = surface > 0 ? double(cell.last.reusedPixels) / surface : 0.0;
        const double leftMs = cell.stages.eye[0].mean, rightMs = cell.stages.eye[1].mean;
        double ratio = leftMs > 0 ? rightMs / leftMs : 0.0;  // of the means
        char psnr[32], line[1024];
        if (c == 0) std::snprintf(psnr, sizeof psnr, "ref");
        else std::snprintf(psnr, sizeof psnr, "%.1f", q.psnr);  // prints inf for identical images
        std::snprintf(line, sizeof line,
                      "| %ux%u | %g | %s | %.2f / %.2f / %.2f / %.2f | %s | %s | %s | %.2f | %.1f%% (%.1f%%) | %s | "
                      "%.2f%% | %s |\n",
                      row.photons, row.photons, row.radius, stereoModeName(modes[c]), cell.frame.mean, cell.frame.p50,
                      cell.frame.p99, cell.frame.max, meanP99(cell.stages.eye[0], 3).c_str(),
                      meanP99(cell.stages.eye[1], 3).c_str(), meanP99(cell.stages.scatter, 3).c_str(), ratio,
                      100.0 * reuse, 100.0 * reuseOfSurface, psnr, 100.0 * q.fractionOver1Percent,
                      ok ? "ok" : "MISMATCH");
        details += line;
        nlohmann::json json5 = {
            {"table", 5}, {"scene", scene.name}, {"photons", row.photons * row.photons}, {"photons_grid", row.photons},
            {"radius", row.radius}, {"stereo", stereoModeName(modes[c])}, {"width", rig.width},
            {"height", rig.height}, {"ipd_m", rig.ipd}, {"frame_ms", cell.frame.mean}, {"left_eye_ms", leftMs},
            {"right_eye_ms", rightMs}, {"scatter_ms", cell.stages.scatter.mean}, {"right_left_ratio", ratio},
            {"reused_fraction", reuse}, {"reused_of_surface_fraction", reuseOfSurface},
            {"psnr_db", c == 0 || std::isinf(q.psnr) ? nlohmann::json() : nlohmann::json(q.psnr)},
            {"over_1pct_fraction", q.fractionOver1Percent}, {"check", ok ? "ok" : "MISMATCH"}};
        json5.update(cell.latencyJson());
        json.push_back(json5);
      }
      std::fflush(stdout);
    }
    std::printf("\nTable 5%s per eye (ms per frame over %d timed frames; frame: mean / p50 / p99 / max, eyes and "
                "scatter: mean / p99; right/left of the means):\n\n| photons | radius | stereo | "
                "frame (mean / p50 / p99 / max) | left eye | right eye | of which scatter | right/left | "
                "reused (of surface pixels) | PSNR dB | >1%% | check |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|\n%s",
                si == 0 ? "" : " (other scenes)", args.frames, details.c_str());
  }
  return failures;
}

// The foveation suite's frames (its headings state them): 512x512 photons, r = 0.05, the paper's
// photon-map-only shading; `mask` null for full resolution.
RenderOptions foveationBenchOptions(const FoveationMask* mask) {
  RenderOptions o;
  o.photonsX = o.photonsY = 512;
  o.gather.mode = ShadingMode::PhotonMapOnly;
  o.gather.density.radius = 0.05f;
  o.foveation.mask = mask;
  return o;
}

// Temporal flicker of foveated rendering with a static head and a moving gaze (smooth pursuit
// around a circle of 0.1 image widths, ~10 deg, in 2 s at 90 Hz: about 31 deg/s), without and
// with TAA: the mean absolute difference of consecutive displayed (sRGB) left-eye frames. The
// full-resolution image does not change (static head, fixed photons), so all of it is the mask's
// motion. Quality: PSNR against full resolution within 5 deg of each frame's gaze, and overall.
int runFlicker(const FrameBenchArgs& args, const Scene& scene, FrameRenderer& renderer, const StereoRig& rig,
               const FoveationMask& mask, const Image& fullResolution, nlohmann::json& json) {
  const int warmup = std::max(args.warmup, 2), frames = std::max(args.frames, 4);
  const double periodFrames = 180.0;
  EyeCamera camera = rig.eye(Eye::Left);
  std::vector<Vec3> directions(size_t(rig.width) * rig.height);
  for (int y = 0; y < rig.height; ++y)
    for (int x = 0; x < rig.width; ++x) directions[size_t(y) * rig.width + x] = camera.generateRay(x + 0.5f, y + 0.5f).dir;
  struct Row {
    std::string name;
    bool taa;
    float blend;
  };
  const std::vector<Row> rows = {{"foveated, no TAA", false, 1.0f}, {"foveated + TAA, blend 0.1", true, 0.1f},
                                 {"foveated + TAA, blend 0.2", true, 0.2f}};
  std::printf("\nTemporal flicker on %s (%s backend): scene %s, both eyes %dx%d, static head, gaze in smooth pursuit "
              "around a circle of radius 0.1 image widths (period %.0f frames at 90 Hz), linear-MAR mask, %d frames "
              "measured after %d; times mean / p99 over them (p99 by nearest rank: the max under 100). Flicker: mean "
              "absolute difference of consecutive displayed left-eye frames, in 8-bit levels (the full-resolution "
              "image does not change). PSNR: against full resolution, left eye.\n\n"
              "| variant | flicker (levels) | of no TAA | PSNR <= 5 deg of gaze | PSNR whole image | TAA ms (both "
              "eyes, mean / p99) | history kept | eye pass ms (both, mean / p99) | check |\n"
              "|---|---|---|---|---|---|---|---|---|\n",
              renderer.deviceName().c_str(), renderer.name().c_str(), scene.name.c_str(), rig.width, rig.height,
              periodFrames, frames, warmup);
  int failures = 0;
  double noTaaFlicker = 0;
  for (size_t r = 0; r < rows.size(); ++r) {
    RenderOptions o = foveationBenchOptions(&mask);
    o.temporal.enabled = rows[r].taa;
    o.temporal.taa.blend = rows[r].blend;
    renderer.resetHistory();
    Image previous;
    double flicker = 0, foveaMse = 0, wholeMse = 0, kept = 0;
    StageSamples timed;  // the measured frames' stage timings
    for (int f = 0; f < warmup + frames; ++f) {
      double angle = 2.0 * kPi * double(f) / periodFrames;
      float gx = 0.5f + 0.1f * float(std::cos(angle));
      float gy = 0.5f + 0.1f * float(std::sin(angle)) * float(rig.width) / float(rig.height);
      o.foveation.gaze[0][0] = gx, o.foveation.gaze[0][1] = gy;
      o.foveation.verge = true;
      FrameResult frame = renderer.render(rig, o, true);
      const Image& shown = frame.eyes[0].image;
      if (f >= warmup) {
        flicker += compareDisplayed(shown, previous).meanAbsoluteDifference;
        int px, py;
        o.foveation.gazePixel(0, rig.width, rig.height, px, py);
        const Vec3 gaze = directions[size_t(py) * rig.width + px];
        const float cos5 = std::cos(5.0f * kPi / 180.0f);
        std::vector<uint8_t> fovea(directions.size());
        for (size_t i = 0; i < fovea.size(); ++i) fovea[i] = dot(directions[i], gaze) >= cos5 ? 1 : 0;
        foveaMse += compareDisplayed(shown, fullResolution, fovea).meanSquaredError;
        wholeMse += compareDisplayed(shown, fullResolution).meanSquaredError;
        timed.add(frame.timings);
        kept += double(frame.historyPixels[0] + frame.historyPixels[1]) / (2.0 * double(shown.pixels.size()));
      }
      previous = shown;
    }
    flicker = 255.0 * flicker / frames, kept /= frames;
    const StageStats stages(timed);
    // PSNR of the mean squared error over the frames (a frame can match exactly: infinite PSNR).
    const double foveaPsnr = 10.0 * std::log10(1.0 / std::max(foveaMse / frames, 1e-30));
    const double wholePsnr = 10.0 * std::log10(1.0 / std::max(wholeMse / frames, 1e-30));
    if (r == 0) noTaaFlicker = flicker;
    const double ratio = flicker / std::max(noTaaFlicker, 1e-12);
    // Self-check: TAA must not blur what the viewer looks at.
    bool ok = foveaPsnr >= 40.0;
    failures += ok ? 0 : 1;
    std::printf("| %s | %.3f | %.2f | %.1f | %.1f | %s | %.1f%% | %s | %s |\n", rows[r].name.c_str(), flicker, ratio,
                foveaPsnr, wholePsnr, meanP99(stages.temporal, 3).c_str(), 100.0 * kept,
                meanP99(stages.eyePass, 3).c_str(), ok ? "ok" : "MISMATCH");
    json.push_back({{"suite", "foveation-flicker"}, {"scene", scene.name}, {"variant", rows[r].name},
                    {"width", rig.width}, {"height", rig.height}, {"taa", rows[r].taa}, {"taa_blend", rows[r].blend},
                    {"frames", frames}, {"flicker_levels", flicker}, {"flicker_of_no_taa", ratio},
                    {"fovea_psnr_db", foveaPsnr}, {"whole_psnr_db", wholePsnr}, {"taa_ms", stages.temporal.mean},
                    {"history_kept_fraction", kept}, {"eye_pass_ms", stages.eyePass.mean}, {"stages", stages.json()},
                    {"check", ok ? "ok" : "MISMATCH"}});
    std::fflush(stdout);
  }
  renderer.resetHistory();
  return failures;
}

// Foveated rendering against full resolution: shaded samples, eye-pass time, and quality in rings
// of eccentricity around the gaze (PSNR of the displayed image against the full-resolution one).
int runFoveation(const FrameBenchArgs& args, const Scene& scene, FrameRenderer& renderer, const StereoRig& rig,
                 nlohmann::json& json) {
  MaskParams params = maskParamsForRig(rig);
  FoveationMask linear = generateFoveationMask(params);
  params.acuity.kind = AcuityKind::GeislerPerry;
  FoveationMask geislerPerry = generateFoveationMask(params);
  struct Column {
    std::string name;
    const FoveationMask* mask;
    float gazeX, gazeY;
    StereoMode stereo = StereoMode::Separate;
  };
  const std::vector<Column> columns = {{"full resolution", nullptr, 0.5f, 0.5f},
                                       {"foveated, linear MAR", &linear, 0.5f, 0.5f},
                                       {"foveated, Geisler-Perry", &geislerPerry, 0.5f, 0.5f},
                                       {"foveated, linear MAR, gaze (0.3, 0.6)", &linear, 0.3f, 0.6f},
                                       {"foveated, linear MAR, stereo gather", &linear, 0.5f, 0.5f, StereoMode::Gather}};
  const std::vector<std::pair<float, float>> rings = {{0, 5}, {5, 10}, {10, 20}, {20, 40}, {40, 180}};
  std::printf("\nFoveated rendering on %s (%s backend): scene %s, both eyes %dx%d, 512x512 photons, r = 0.05, radius "
              "estimate, photon-map-only shading, %d timed frames after %d warm-up; times mean / p99 over them (p99 by "
              "nearest rank: the max under 100 frames). Masks: %zu vertices (linear MAR, "
              "omega0 = 1/48 deg, m = 0.022, %g deg margin), %zu (Geisler-Perry). PSNR: left eye against full "
              "resolution, displayed (sRGB), in rings of eccentricity from the gaze.\n\n"
              "| variant | frame ms (mean / p99) | eye pass ms (both, mean / p99) | of which reconstruction | "
              "samples per eye | fewer | eye pass speed-up | PSNR 0-5 deg | 5-10 | 10-20 | 20-40 | >40 | check |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
              renderer.deviceName().c_str(), renderer.name().c_str(), scene.name.c_str(), rig.width, rig.height,
              args.frames, args.warmup, linear.offsets.size(), double(params.acuity.gazeMarginDeg),
              geislerPerry.offsets.size());
  int failures = 0;
  double fullEyeMs = 0;
  FrameResult reference;
  std::string reuseNotes;
  for (size_t c = 0; c < columns.size(); ++c) {
    RenderOptions o = foveationBenchOptions(columns[c].mask);
    o.stereo = columns[c].stereo;
    o.foveation.gaze[0][0] = columns[c].gazeX, o.foveation.gaze[0][1] = columns[c].gazeY;
    o.foveation.verge = true;  // both eyes fixate one point
    CellResult cell = timeCell(renderer, rig, o, args.warmup, args.frames);
    const double eyeMs = cell.stages.eyePass.mean;
    if (c == 0) fullEyeMs = eyeMs, reference = cell.last;
    // Eccentricity of each pixel of the left eye from the gaze direction.
    EyeCamera camera = rig.eye(Eye::Left);
    int gx, gy;
    o.foveation.gazePixel(0, rig.width, rig.height, gx, gy);
    Vec3 gazeDir = camera.generateRay(gx + 0.5f, gy + 0.5f).dir;
    std::vector<float> eccentricity(size_t(rig.width) * rig.height);
    for (int y = 0; y < rig.height; ++y)
      for (int x = 0; x < rig.width; ++x)
        eccentricity[size_t(y) * rig.width + x] =
            std::acos(std::clamp(dot(camera.generateRay(x + 0.5f, y + 0.5f).dir, gazeDir), -1.0f, 1.0f)) * 180.0f / kPi;
    std::vector<double> psnr;
    for (auto [lo, hi] : rings) {
      std::vector<uint8_t> ring(eccentricity.size());
      for (size_t i = 0; i < ring.size(); ++i) ring[i] = eccentricity[i] >= lo && eccentricity[i] < hi ? 1 : 0;
      psnr.push_back(compareDisplayed(cell.last.eyes[0].image, reference.eyes[0].image, ring).psnr);
    }
    double pixels = double(rig.width) * rig.height;
    double samples = double(cell.last.shadedSamples[0]);
    // Self-check: the fovea of a foveated image is the full-resolution image there.
    bool ok = c == 0 || psnr[0] >= 40.0;
    failures += ok ? 0 : 1;
    std::printf("| %s | %s | %s | %s | %.0f | %.1fx | %.2fx |", columns[c].name.c_str(),
                meanP99(cell.frame, 2).c_str(), meanP99(cell.stages.eyePass, 3).c_str(),
                meanP99(cell.stages.reconstruct, 3).c_str(), samples, pixels / std::max(samples, 1.0),
                fullEyeMs / std::max(eyeMs, 1e-9));
    for (double p : psnr) std::printf(c == 0 ? " ref |" : " %.1f |", p);
    std::printf(" %s |\n", ok ? "ok" : "MISMATCH");
    const double rightLeft = cell.stages.eye[1].mean / std::max(cell.stages.eye[0].mean, 1e-9);
    const double reusedShare = double(cell.reusedPixels) / std::max(double(cell.last.shadedSamples[1]), 1.0);
    if (columns[c].stereo != StereoMode::Separate)
      reuseNotes += "- " + columns[c].name + ": the right eye took " + std::to_string(int(100.0 * reusedShare + 0.5)) +
                    "% of its vertices from the left; right/left eye time " + std::to_string(rightLeft).substr(0, 4) + "\n";
    nlohmann::json ringJson = nlohmann::json::array();
    for (size_t r = 0; r < rings.size(); ++r)
      ringJson.push_back({{"from_deg", rings[r].first}, {"to_deg", rings[r].second},
                          {"psnr_db", c == 0 || std::isinf(psnr[r]) ? nlohmann::json() : nlohmann::json(psnr[r])}});
    nlohmann::json row = {{"suite", "foveation"}, {"scene", scene.name}, {"variant", columns[c].name},
                          {"width", rig.width}, {"height", rig.height}, {"frame_ms", cell.frame.mean},
                          {"eye_pass_ms", eyeMs}, {"reconstruct_ms", cell.stages.reconstruct.mean},
                          {"samples_per_eye", samples}, {"pixels_per_eye", pixels},
                          {"eye_pass_speedup", fullEyeMs / std::max(eyeMs, 1e-9)}, {"rings", ringJson},
                          {"stereo", stereoModeName(columns[c].stereo)}, {"right_left_ratio", rightLeft},
                          {"reused_vertex_fraction", reusedShare}, {"check", ok ? "ok" : "MISMATCH"}};
    row.update(cell.latencyJson());
    json.push_back(row);
    std::fflush(stdout);
  }
  if (!reuseNotes.empty()) std::printf("\n%s", reuseNotes.c_str());
  return failures + runFlicker(args, scene, renderer, rig, linear, reference.eyes[0].image, json);
}

#ifdef PVR_HAVE_CUDA
// The photon pass's rays per second beside the ray kernels' (the rays suite), at growing photon
// counts, over the binary BVH and the 8-wide one: a row each, returned for the table after the
// rays'. At a frame's 512^2 the pass waits on its longest paths (the GPU is not filled), so its
// rate per ray follows how many rays a scene's paths cast; from 1024^2 it fills the GPU and the
// rate is that of its traversal and shading.
std::string photonPassRows(const std::string& name, const Scene& scene, const WideBvh& wide, CudaFrameBackend& gpu,
                           const CpuBackend& cpu, int repeats, nlohmann::json& json, int& failures) {
  std::string rows;
  for (uint32_t side : {256u, 512u, 1024u, 2048u}) {
    RenderOptions o;
    o.photonsX = o.photonsY = side;
    o.gather.mode = ShadingMode::Full;
    const PhotonTraceParams tp = o.photonTraceParams();
    const PhotonPaths paths = countPhotonPaths(scene.view(), cpu.intersector(), tp);
    auto mrays = [&](double ms) { return ms > 0 ? double(paths.rays) / (ms * 1e3) : 0.0; };
    for (PhotonPassBvh bvh : {PhotonPassBvh::Binary, PhotonPassBvh::Wide}) {
      gpu.setPhotonPassBvh(bvh, &wide);
      const char* bvhName = bvh == PhotonPassBvh::Wide ? "8-wide" : "binary";
      size_t gpuStored = 0;
      const LatencyStats t = latencyStats(timePhotonTrace(gpu, tp, repeats, gpuStored));
      const double storedDifference = std::fabs(double(gpuStored) - double(paths.stored));
      const bool ok = storedDifference <= 1e-3 * double(tp.photonCount);
      failures += ok ? 0 : 1;
      char row[512];
      std::snprintf(row, sizeof row, "| %s | %s | %ux%u | %.2f M (%.2f) | %zu / %llu | %.3f / %.3f | %.0f / %.0f | %s |\n",
                    name.c_str(), bvhName, side, side, paths.rays * 1e-6, double(paths.rays) / double(tp.photonCount),
                    gpuStored, (unsigned long long)paths.stored, t.p50, t.p99, mrays(t.p50), mrays(t.p99),
                    ok ? "ok" : "MISMATCH");
      rows += row;
      json.push_back({{"suite", "rays"}, {"stage", "photon pass"}, {"scene", name}, {"bvh", bvhName},
                      {"photons", tp.photonCount}, {"max_depth", tp.maxDepth}, {"rays", paths.rays},
                      {"stored_gpu", gpuStored}, {"stored_cpu", paths.stored}, {"repeats", repeats}, {"pass", t},
                      {"mrays_s", mrays(t.p50)}, {"p99_mrays_s", mrays(t.p99)}, {"check", ok ? "ok" : "MISMATCH"}});
    }
  }
  gpu.setPhotonPassBvh(PhotonPassBvh::Binary);
  return rows;
}

int runRays(const FrameBenchArgs& args, nlohmann::json& json) {
  int failures = 0;
  const int repeats = 20;
  std::string photonRows;  // the photon pass's table, printed after the rays'
  std::printf("\nRay throughput of the CUDA traversal, both eyes, one ray per pixel, %d runs (CUDA events; each "
              "after its own warm-up run): Mrays/s at the median run time / at the p99 run time (p99 by nearest "
              "rank: the slowest under 100 runs). Two BVH layouts, both built by Embree (SAH + spatial splits), "
              "both with the same watertight triangle test: binary (64-byte nodes, 4 triangles a leaf) and "
              "8-wide with 8-bit quantized child boxes (80-byte nodes, 3 triangles a leaf); the renderer's kernels "
              "use the binary one; the traversal stack in shared memory (the renderer's) or in local memory\n\n"
              "| scene | triangles | BVH | nodes | refs | MiB | build ms | SAH cost | eye size | primary Mrays/s "
              "(median / p99) | shadow Mrays/s (median / p99) | diffuse Mrays/s (median / p99) | check vs Embree |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
              repeats);
  for (const std::string& name : splitList(args.raysScene)) {
    Scene scene = loadScene(name);
    StereoRig rig = benchRig(scene, args);
    CudaFrameBackend gpu(scene);
    CpuBackend cpu(scene);
    const Bvh binary = Bvh::build(scene);
    const WideBvh wide = WideBvh::build(scene);
    for (int variant = 0; variant < 4; ++variant) {
      const bool isWide = variant < 2, sharedStack = variant % 2 == 0;
      GpuRayBench bench = isWide ? GpuRayBench(gpu, wide) : GpuRayBench(gpu, binary);
      // One run per call, so that every run's time is kept (measure reports the median of its runs).
      GpuRayThroughput t;
      std::vector<double> primaryMs, shadowMs, diffuseMs;
      for (int r = 0; r < repeats; ++r) {
        t = bench.measure(rig, 1, sharedStack);
        primaryMs.push_back(t.primaryMs), shadowMs.push_back(t.shadowMs), diffuseMs.push_back(t.diffuseMs);
      }
      const LatencyStats primary = latencyStats(primaryMs), shadow = latencyStats(shadowMs),
                         diffuse = latencyStats(diffuseMs);
      // Check: the left eye's pixel-centre hits against Embree on the CPU, every 13th pixel.
      EyeCamera camera = rig.eye(Eye::Left);
      size_t checked = 0, agree = 0;
      for (size_t i = 0; i < t.leftPrimaryHits.size(); i += 13) {
        int x = int(i % rig.width), y = int(i / rig.width);
        Hit h;
        bool hit = cpu.intersector().intersect(camera.generateRay(x + 0.5f, y + 0.5f), INFINITY, h);
        const Hit& g = t.leftPrimaryHits[i];
        ++checked;
        if (hit == g.valid() && (!hit || h.primId == g.primId || std::fabs(h.t - g.t) <= 1e-4f * h.t)) ++agree;
      }
      double agreement = double(agree) / double(std::max<size_t>(checked, 1));
      bool ok = agreement >= 0.999;
      failures += ok ? 0 : 1;
      const BvhBuildStats& s = isWide ? wide.stats() : binary.stats();
      const double mib = double(isWide ? wide.memoryBytes() : binary.memoryBytes()) / (1024.0 * 1024.0);
      const std::string layoutName = std::string(isWide ? "8-wide, quantized" : "binary") +
                                     (sharedStack ? "" : ", local-memory stack");
      auto mrays = [](uint64_t rays, double ms) { return ms > 0 ? double(rays) / (ms * 1e3) : 0.0; };
      std::printf("| %s | %u | %s | %u | %u | %.1f | %.0f | %.1f | %dx%d x2 | %.0f / %.0f | %.0f / %.0f | %.0f / %.0f "
                  "| %s (%.4f%% agree) |\n",
                  name.c_str(), s.inputTriangles, layoutName.c_str(), s.nodes, s.triangleReferences, mib, s.buildMs, s.sahCost,
                  rig.width, rig.height, mrays(t.primaryRays, primary.p50), mrays(t.primaryRays, primary.p99),
                  mrays(t.shadowRays, shadow.p50), mrays(t.shadowRays, shadow.p99), mrays(t.diffuseRays, diffuse.p50),
                  mrays(t.diffuseRays, diffuse.p99), ok ? "ok" : "MISMATCH", 100.0 * agreement);
      // *_ms stay the medians (now the nearest-rank p50) and *_mrays_s their throughputs; the objects
      // "primary", "shadow" and "diffuse" hold the run times' mean, p50, p99 and max in ms.
      json.push_back({{"suite", "rays"}, {"scene", name}, {"bvh", isWide ? "wide8" : "binary"}, {"stack", sharedStack ? "shared" : "local"},
                      {"triangles", s.inputTriangles}, {"bvh_nodes", s.nodes}, {"bvh_refs", s.triangleReferences},
                      {"bvh_mib", mib}, {"bvh_build_ms", s.buildMs}, {"sah_cost", s.sahCost},
                      {"bvh_depth", s.maxDepth}, {"width", rig.width}, {"height", rig.height},
                      {"repeats", repeats}, {"primary_rays", t.primaryRays}, {"primary_ms", primary.p50},
                      {"shadow_rays", t.shadowRays}, {"shadow_ms", shadow.p50}, {"diffuse_rays", t.diffuseRays},
                      {"diffuse_ms", diffuse.p50}, {"primary_mrays_s", mrays(t.primaryRays, primary.p50)},
                      {"shadow_mrays_s", mrays(t.shadowRays, shadow.p50)},
                      {"diffuse_mrays_s", mrays(t.diffuseRays, diffuse.p50)},
                      {"primary_p99_mrays_s", mrays(t.primaryRays, primary.p99)},
                      {"shadow_p99_mrays_s", mrays(t.shadowRays, shadow.p99)},
                      {"diffuse_p99_mrays_s", mrays(t.diffuseRays, diffuse.p99)}, {"primary", primary},
                      {"shadow", shadow}, {"diffuse", diffuse}, {"check_agreement", agreement}});
      std::fflush(stdout);
    }
    photonRows += photonPassRows(name, scene, wide, gpu, cpu, repeats, json, failures);
  }
  std::printf("\nPhoton pass (trace, scan of the counts, compaction: a frame's trace stage) over the binary BVH (the "
              "frames') and the 8-wide one, full shading's photons "
              "(no direct photons stored), up to 8 interactions a path; %d runs each (CUDA events; after a warm-up "
              "run). Rays: the paths' segments, counted on the CPU by the same code; stored photons GPU against CPU "
              "(the same paths but for rounding, which may tip a few: they differ by at most 0.1 %% of the emitted "
              "photons)\n\n"
              "| scene | BVH | photons | rays (per photon) | stored GPU / CPU | pass ms (median / p99) | Mrays/s (median / p99) | "
              "check |\n|---|---|---|---|---|---|---|---|\n%s",
              repeats, photonRows.c_str());
  return failures;
}

int runGrid(const FrameBenchArgs& args, nlohmann::json& json) {
  Scene scene = loadScene(args.scene);
  CudaFrameBackend gpu(scene);
  PhotonTraceParams params;
  params.photonCount = 1u << 20;
  params.storeDirect = true;
  std::vector<Photon> photons = gpu.tracePhotonsToHost(params);
  photons.resize(std::min<size_t>(photons.size(), 1u << 20));
  int failures = 0;
  const int repeats = 50;
  std::printf("\nHash-grid build on the GPU: %zu photons traced in %s; keys, CUB radix sort of (cell, index), "
              "startIdx by scan, photons gathered; %d builds (CUDA events; each after its own warm-up build): "
              "median / p99 / max (p99 by nearest rank: the max under 100 builds)\n\n"
              "| photons | radius | cells | GPU build ms (median / p99 / max) | CPU build ms | check vs CPU |\n"
              "|---|---|---|---|---|---|\n",
              photons.size(), scene.name.c_str(), repeats);
  for (float radius : {0.02f, 0.05f, 0.1f, 0.2f}) {
    // One timed build per call, so that every build's time is kept (buildHashGrid reports the
    // median of its builds); the last call also downloads the grid for the check.
    GpuHashGridCopy copy;
    std::vector<double> buildMs;
    for (int r = 0; r < repeats; ++r)
      buildMs.push_back(gpu.buildHashGrid(photons, radius, 1, r + 1 == repeats ? &copy : nullptr));
    const LatencyStats gpuBuild = latencyStats(buildMs);
    auto start = Clock::now();
    HashGrid cpu = HashGrid::build(photons, radius);
    double cpuMs = msSince(start);
    bool ok = copy.cellStart == cpu.cellStart() && copy.sortedToInput == cpu.sortedToInput();
    failures += ok ? 0 : 1;
    std::printf("| %zu | %g | %zu | %.3f / %.3f / %.3f | %.1f | %s |\n", photons.size(), radius,
                cpu.cellStart().size() - 1, gpuBuild.p50, gpuBuild.p99, gpuBuild.max, cpuMs,
                ok ? "ok (identical)" : "MISMATCH");
    // gpu_build_ms stays the median (now the nearest-rank p50); "gpu_build" holds mean, p50, p99, max.
    json.push_back({{"suite", "grid"}, {"photons", photons.size()}, {"radius", radius},
                    {"cells", cpu.cellStart().size() - 1}, {"repeats", repeats}, {"gpu_build_ms", gpuBuild.p50},
                    {"gpu_build", gpuBuild}, {"cpu_build_ms", cpuMs}, {"check", ok ? "ok" : "MISMATCH"}});
  }
  std::printf("\nKd-tree build on the GPU (level by level: ranks by three stable radix sorts, then per level node "
              "bounds and one radix sort of the slots by (node, rank along its axis)) against the CPU build "
              "(recursive nth_element, TBB), the same tree; %d builds each\n\n"
              "| photons | GPU build ms (median / p99 / max) | CPU build ms | check vs CPU |\n|---|---|---|---|\n",
              repeats);
  for (size_t count : {size_t(1) << 16, size_t(1) << 18, photons.size()}) {
    std::vector<Photon> subset(photons.begin(), photons.begin() + std::min(count, photons.size()));
    GpuKdTreeCopy copy;
    std::vector<double> buildMs;
    for (int r = 0; r < repeats; ++r) buildMs.push_back(gpu.buildKdTree(subset, 1, r + 1 == repeats ? &copy : nullptr));
    const LatencyStats gpuBuild = latencyStats(buildMs);
    auto start = Clock::now();
    KdTree cpu = KdTree::build(subset);
    double cpuMs = msSince(start);
    bool ok = copy.nodeToInput == cpu.nodeToInput() &&
              std::equal(copy.axes.begin(), copy.axes.end(), cpu.view().axes);
    failures += ok ? 0 : 1;
    std::printf("| %zu | %.3f / %.3f / %.3f | %.1f | %s |\n", subset.size(), gpuBuild.p50, gpuBuild.p99, gpuBuild.max,
                cpuMs, ok ? "ok (identical)" : "MISMATCH");
    json.push_back({{"suite", "grid"}, {"map", "kd-tree"}, {"photons", subset.size()}, {"repeats", repeats},
                    {"gpu_build_ms", gpuBuild.p50}, {"gpu_build", gpuBuild}, {"cpu_build_ms", cpuMs},
                    {"check", ok ? "ok" : "MISMATCH"}});
  }
  return failures;
}
#endif

}  // namespace

struct FrameRays {
  uint64_t photon = 0;  ///< photon paths' segments
  uint64_t eye = 0;     ///< both eyes: camera and specular-chain rays plus shadow rays
};

// The rays of a separate (no reuse) full-resolution frame with options o.
FrameRays countFrameRays(const Scene& scene, const StereoRig& rig, const RenderOptions& o) {
  CpuBackend backend(scene);
  SceneView view = scene.view();
  FrameRays rays;
  rays.photon = countPhotonPaths(view, backend.intersector(), o.photonTraceParams()).rays;
  // Eye paths never depend on the photon map's contents: an empty one casts the same rays.
  HashGrid grid = HashGrid::build({}, o.gather.density.radius);
  CountingIntersector eyeCounter{backend.intersector()};
  for (Eye eye : {Eye::Left, Eye::Right}) {
    const EyeCamera camera = rig.eye(eye);
    parallelForTiles("count eye rays", camera.height, camera.width, 16, [&](int y0, int y1, int x0, int x1) {
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) shadePixel(view, eyeCounter, grid.view(), o.gather, camera, eye, x, y);
    });
  }
  rays.eye = eyeCounter.closest + eyeCounter.shadow;
  return rays;
}


// Textured scenes with full shading (the real-time configuration): separate and gather frames,
// the same gather frame without colour textures (what sampling costs), and each image's error
// against the view's converged reference (progressive photon mapping from the cells' radius,
// pixel-centre filter as the cells', a shadow ray to every light).
int runScenes(const FrameBenchArgs& args, BackendKind kind, nlohmann::json& json) {
  int failures = 0;
  if (args.referencePasses < 2 || args.referencePasses > kMaxReferencePasses)
    throw Error("--reference-passes must be between 2 and " + std::to_string(kMaxReferencePasses));
  std::printf("\nTextured scenes: full shading (direct light by shadow rays, photon map for the rest), hash grid, "
              "radius estimate, hybrid kernel, %d timed frames per cell after %d of warm-up; error against the view's "
              "converged reference (%d progressive passes of 1024x1024 photons from the cells' radius, alpha 0.7, "
              "kd-tree, a shadow ray to every light, pixel centres): relMSE and SSIM of the left / right eye, and rMAD (mean "
              "absolute difference over the mean); eye rays and density: both eyes' stages within the eye passes\n\n",
              args.frames, args.warmup, args.referencePasses);
  std::printf("| scene | eyes | photons | radius (of diagonal) | variant | frame (mean / p99) | trace | build | left eye | "
              "right eye | eye rays | density | relMSE L / R | SSIM L / R | rMAD L / R | check |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& name : splitList(args.scenes)) {
    Scene scene;
    try {
      scene = loadScene(name);
    } catch (const Error& e) {  // the classic scenes are not shipped: say so and go on
      std::printf("| %s | skipped: %s |\n", name.c_str(), e.what());
      continue;
    }
    StereoRig rig = benchRig(scene, args);
    Scene plain = scene.withoutColourTextures();
    std::unique_ptr<FrameRenderer> renderer = makeFrameRenderer(kind, scene);
    std::unique_ptr<FrameRenderer> plainRenderer = makeFrameRenderer(kind, plain);
    const float diagonal = length(scene.bounds().extent());
    // The built-in boxes (the per-ray yardstick) keep the paper's radius; the cathedrals take --scene-radius.
    const std::vector<std::string> builtins = builtinSceneNames();
    const bool builtin = std::find(builtins.begin(), builtins.end(), name) != builtins.end();
    const float radius = builtin ? RenderOptions().gather.density.radius : args.sceneRadius;
    RenderOptions o;
    o.photonsX = o.photonsY = 512;
    o.gather.density.radius = radius;
    o.gather.mode = ShadingMode::Full;
    Image converged[2];
    double referenceRelMse[2] = {0, 0};
    {
      RenderOptions ro = o;
      ro.photonsX = ro.photonsY = 1024;
      ro.gather.punctualShadowRays = 0;  // no light-selection noise in the reference
      ro.gather.seed = 0x5eed;           // independent of the cells' numbers
      // The shrinking radius would need more hash-grid cells than allowed where photons spread
      // over a large extent (Sibenik's surroundings): the kd-tree has no such limit.
      ro.map = PhotonMapKind::KdTree;
      ReferenceSettings settings;
      settings.boxFilter = false;  // the cells' pixel centres: the rows measure the estimate, not aliasing
      ProgressiveReference reference(*renderer, rig, ro, settings);
      for (int i = 0; i < args.referencePasses; ++i) reference.addPass();
      for (int e = 0; e < 2; ++e) converged[e] = reference.image(Eye(e)), referenceRelMse[e] = reference.estimatedRelMse(Eye(e));
      std::printf("| %s | reference: %d passes, radius %g -> %.4g, estimated relMSE (variance) %.2g / %.2g |\n",
                  scene.name.c_str(), reference.passes(), radius, reference.radiusOfPass(reference.passes() - 1),
                  referenceRelMse[0], referenceRelMse[1]);
    }
    struct Cell {
      const char* name;
      FrameRenderer* renderer;
      StereoMode stereo;
      int shadowRays;  ///< to the punctual lights per gather point (0: one per light)
      RaySchedule schedule = RaySchedule::Auto;
    };
    // The textured cells choose one punctual light per shadow ray; "every light" shows what one
    // exact ray per light costs, the untextured cell what texture sampling costs. On the GPU the last
    // three fix the ray schedule (all rays in the eye kernel, first hits apart, shadow rays apart too)
    // and must give the gather cell's image to rounding; "gather" takes RaySchedule::Auto's choice.
    const Cell allCells[] = {{"separate", renderer.get(), StereoMode::Separate, 1},
                             {"gather", renderer.get(), StereoMode::Gather, 1},
                             {"gather, a ray to every light", renderer.get(), StereoMode::Gather, 0},
                             {"gather, no colour textures", plainRenderer.get(), StereoMode::Gather, 1},
                             {"gather, all rays in the eye kernel", renderer.get(), StereoMode::Gather, 1, RaySchedule::InKernel},
                             {"gather, first hits apart", renderer.get(), StereoMode::Gather, 1, RaySchedule::FirstHits},
                             {"gather, first hits and shadow rays apart", renderer.get(), StereoMode::Gather, 1, RaySchedule::Deferred}};
    std::vector<Cell> cells(allCells, allCells + 2);
    if (scene.punctualLights().size() > 1) cells.push_back(allCells[2]);
    if (scene.textureCount() > 0) cells.push_back(allCells[3]);  // no textures: nothing to leave out
    if (kind == BackendKind::Cuda)  // the CPU traces in place
      for (int k = 4; k < 7; ++k) cells.push_back(allCells[k]);
    FrameResult gatherFrame;
    const FrameRays rays = countFrameRays(scene, rig, o);
    double gatherEyePassMs = 0, untexturedEyePassMs = 0;
    for (size_t c = 0; c < cells.size(); ++c) {
      RenderOptions co = o;
      co.stereo = cells[c].stereo;
      co.gather.punctualShadowRays = cells[c].shadowRays;
      co.raySchedule = cells[c].schedule;
      CellResult r = timeCell(*cells[c].renderer, rig, co, args.warmup, args.frames);
      const bool untextured = cells[c].renderer == plainRenderer.get();
      if (c == 1) gatherEyePassMs = r.stages.eyePass.mean, gatherFrame = r.last;
      if (untextured) untexturedEyePassMs = r.stages.eyePass.mean;
      double error[2] = {compareImages(converged[0], r.last.eyes[0].image).relativeMad,
                         compareImages(converged[1], r.last.eyes[1].image).relativeMad};
      const ReferenceError ref[2] = {compareToReference(r.last.eyes[0].image, converged[0]),
                                     compareToReference(r.last.eyes[1].image, converged[1])};
      // Textured frames must converge towards the reference (a broken path shows here); the
      // untextured one must differ from it (textures do something).
      bool ok = !untextured ? error[0] < 0.5 && error[1] < 0.5 : error[0] > 0.01;
      double scheduleRelMse[2] = {0, 0};  // against the gather cell: where rays are traced changes only rounding
      if (cells[c].schedule != RaySchedule::Auto)
        for (int e = 0; e < 2; ++e) {
          scheduleRelMse[e] = compareToReference(r.last.eyes[e].image, gatherFrame.eyes[e].image).relMse;
          // Far below the frame's own error: rounding, and the rare light choice or reuse decision it tips.
          ok = ok && scheduleRelMse[e] < 1e-4 * ref[e].relMse && *r.last.eyes[e].firstPrim == *gatherFrame.eyes[e].firstPrim;
        }
      failures += ok ? 0 : 1;
      std::printf("| %s | %dx%d | 512x512 | %g (%.2f %%) | %s | %s | %s | %s | %s | %s | %.2f | %.2f | %.3f / %.3f | "
                  "%.3f / %.3f | %.3f / %.3f | %s |\n",
                  scene.name.c_str(), rig.width, rig.height, radius, 100.0 * radius / diagonal,
                  cells[c].name, meanP99(r.frame, 2).c_str(), meanP99(r.stages.trace, 2).c_str(),
                  meanP99(r.stages.build, 2).c_str(), meanP99(r.stages.eye[0], 2).c_str(), meanP99(r.stages.eye[1], 2).c_str(),
                  r.stages.rays.mean, r.stages.density.mean, ref[0].relMse, ref[1].relMse, ref[0].ssim, ref[1].ssim,
                  error[0], error[1], ok ? "ok" : "MISMATCH");
      if (c == 1 && kind == BackendKind::Cuda) {
        const int queries = shadowQueriesPerPoint(scene.view(), cells[c].shadowRays);
        std::printf("| %s | gather's ray schedule (auto): %s for the left eye, %s for the right (%d shadow queries per "
                    "point) |\n",
                    scene.name.c_str(), rayScheduleName(eyeRayScheduleFor(queries, false)),
                    rayScheduleName(eyeRayScheduleFor(queries, true)), queries);
      }
      if (cells[c].schedule != RaySchedule::Auto)
        std::printf("| %s | %s: relMSE against the gather cell's image %.2g / %.2g (rounding; must be < 1e-4 of the "
                    "error), the same first hits |\n",
                    scene.name.c_str(), cells[c].name, scheduleRelMse[0], scheduleRelMse[1]);
      nlohmann::json cell = r.latencyJson();
      cell.update({{"suite", "scenes"}, {"scene", scene.name}, {"variant", cells[c].name}, {"backend", renderer->name()},
                   {"device", renderer->deviceName()}, {"eye_size", {rig.width, rig.height}}, {"photons", 512 * 512},
                   {"radius", radius}, {"radius_of_diagonal", radius / diagonal},
                   {"punctual_shadow_rays", cells[c].shadowRays}, {"ray_schedule", rayScheduleName(cells[c].schedule)},
                   {"rel_mse_vs_gather_cell", {scheduleRelMse[0], scheduleRelMse[1]}}, {"punctual_lights", scene.punctualLights().size()},
                   {"triangles", scene.triangleCount()}, {"textures", scene.textureCount()},
                   {"rmad_vs_reference", {error[0], error[1]}}, {"rel_mse_vs_reference", {ref[0].relMse, ref[1].relMse}},
                   {"ssim_vs_reference", {ref[0].ssim, ref[1].ssim}}, {"psnr_vs_reference", {ref[0].psnr, ref[1].psnr}},
                   {"mean_vs_reference", {ref[0].meanRatio, ref[1].meanRatio}}, {"reference_passes", args.referencePasses},
                   {"reference_estimated_rel_mse", {referenceRelMse[0], referenceRelMse[1]}},
                   {"check", ok ? "ok" : "MISMATCH"}});
      if (c == 0) {  // rays per second of the separate frame's stages (mean stage times)
        const double traceS = r.stages.trace.mean * 1e-3, eyeS = (r.stages.eye[0].mean + r.stages.eye[1].mean) * 1e-3;
        const double photonRate = traceS > 0 ? double(rays.photon) / traceS : 0.0;
        const double eyeRate = eyeS > 0 ? double(rays.eye) / eyeS : 0.0;
        std::printf("| %s | rays per frame: %.2f M photon, %.2f M eye (camera, specular chains, shadow); photon trace "
                    "%.0f Mrays/s, eye pass %.0f Mrays/s (density estimates included) |\n",
                    scene.name.c_str(), rays.photon * 1e-6, rays.eye * 1e-6, photonRate * 1e-6, eyeRate * 1e-6);
        cell.update({{"photon_rays", rays.photon}, {"eye_rays", rays.eye}, {"photon_trace_rays_per_s", photonRate},
                     {"eye_pass_rays_per_s", eyeRate}});
      }
      json.push_back(cell);
    }
    if (untexturedEyePassMs > 0)
      std::printf("| %s | texture sampling adds %.1f %% to the eye pass (gather: %.2f ms against %.2f ms without colour "
                  "textures) |\n",
                  scene.name.c_str(), 100.0 * (gatherEyePassMs / untexturedEyePassMs - 1.0), gatherEyePassMs,
                  untexturedEyePassMs);
  }
  return failures;
}

int runFrameBench(const FrameBenchArgs& args) {
  if (args.suite != "tables" && args.suite != "rays" && args.suite != "grid" && args.suite != "stereo" &&
      args.suite != "foveation" && args.suite != "scenes" && args.suite != "quality" && args.suite != "effects" &&
      args.suite != "controller" && args.suite != "all")
    throw Error("--suite must be tables, stereo, foveation, scenes, quality, effects, controller, rays, grid or all, got '" + args.suite + "'");
  if (!args.profileOut.empty() && args.suite != "effects" && args.suite != "controller")
    throw Error("--profile-out is for --suite effects or controller");
  if (!(args.sceneRadius > 0.0f) || !std::isfinite(args.sceneRadius)) throw Error("--scene-radius must be a positive number");
  if (args.frames < 1 || args.frames > 100000) throw Error("--frames must be between 1 and 100000");
  if (args.warmup < 0 || args.warmup > 100000) throw Error("--warmup must be between 0 and 100000");
  if (args.k < 1 || args.k > kMaxKnn) throw Error("--k must be between 1 and " + std::to_string(kMaxKnn));
  BackendKind kind = parseBackendKind(args.backend);
  bool gpuSuite = args.suite == "rays" || args.suite == "grid" || args.suite == "all";
  std::string why;
  if (gpuSuite && (kind == BackendKind::Cpu || !cudaBackendAvailable(&why)))
    throw Error("the " + args.suite + " suite measures the CUDA backend: " +
                (kind == BackendKind::Cpu ? std::string("--backend cpu was given") : why));
  nlohmann::json json = nlohmann::json::array();
  int failures = 0;
  if (args.suite == "tables" || args.suite == "stereo" || args.suite == "foveation" || args.suite == "all") {
    Scene scene = loadScene(args.scene);
    StereoRig rig = benchRig(scene, args);
    std::unique_ptr<FrameRenderer> renderer = makeFrameRenderer(kind, scene);
    if (args.suite == "tables" || args.suite == "all") failures += runTables(args, scene, *renderer, rig, json);
    if (args.suite == "stereo" || args.suite == "all") failures += runStereo(args, *renderer, json);
    if (args.suite == "foveation" || args.suite == "all") failures += runFoveation(args, scene, *renderer, rig, json);
  }
  if (args.suite == "scenes") failures += runScenes(args, kind, json);
  if (args.suite == "quality") failures += runQuality(args, kind, json);
  if (args.suite == "effects") failures += runEffects(args, kind, json);
  if (args.suite == "controller") failures += runControllerBench(args, kind, json);
#ifdef PVR_HAVE_CUDA
  if (args.suite == "rays" || args.suite == "all") failures += runRays(args, json);
  if (args.suite == "grid" || args.suite == "all") failures += runGrid(args, json);
#endif
  if (!args.json.empty()) {
    std::ofstream out(args.json);
    if (!out) throw Error("cannot write '" + args.json + "'");
    out << json.dump(2) << "\n";
    std::printf("\nwrote %s\n", args.json.c_str());
  }
  if (failures) std::printf("\n%d self-check(s) FAILED\n", failures);
  return failures ? 1 : 0;
}

}  // namespace pvr
