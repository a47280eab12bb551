#include "frame_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "pvr/render/renderer.h"
#include "pvr/scene/scene.h"
#include "bench_util.h"
#include "pvr/util/error.h"
#ifdef PVR_HAVE_CUDA
#include "pvr/cuda/cuda_renderer.h"
#endif

namespace pvr {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// One column of one of the paper's tables.
struct Variant {
  std::string name;
  PhotonMapKind map;
  Estimator estimator;
  DensityKernel kernel;
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
  // Columns that compute the same image as column 0 (checked), e.g. single vs hybrid.
  bool sameImage;
};

std::vector<Table> paperTables() {
  const auto grid = PhotonMapKind::HashGrid, kd = PhotonMapKind::KdTree;
  const auto knn = Estimator::Knn, radius = Estimator::Radius;
  const auto hybrid = DensityKernel::Hybrid;
  std::vector<Table> t;
  t.push_back({1, "kd-tree vs hash grid (kNN max-heap, hybrid kernel)",
               {{"kd-tree", kd, knn, hybrid}, {"hash grid", grid, knn, hybrid}},
               {{512, 0.02f, {10.80, 6.15}}, {512, 0.05f, {112.30, 84.50}}, {512, 0.1f, {470.31, 567.70}},
                {256, 0.05f, {12.48, 7.05}}, {256, 0.1f, {67.91, 48.68}}, {256, 0.2f, {314.21, 419.63}},
                {128, 0.05f, {3.58, 3.03}}, {128, 0.1f, {8.17, 5.73}}, {128, 0.2f, {38.81, 27.16}}},
               true});
  t.push_back({2, "heap vs no heap (hash grid, hybrid kernel)",
               {{"heap (kNN)", grid, knn, hybrid}, {"no heap (radius)", grid, radius, hybrid}},
               {{512, 0.02f, {6.61, 3.27}}, {512, 0.05f, {84.87, 8.26}}, {512, 0.1f, {583.50, 23.16}},
                {256, 0.05f, {7.53, 3.50}}, {256, 0.1f, {49.30, 6.54}}, {256, 0.2f, {414.93, 20.16}}},
               false});
  t.push_back({3, "single vs hybrid kernel (hash grid, radius)",
               {{"single", grid, radius, DensityKernel::Single}, {"hybrid", grid, radius, hybrid}},
               {{512, 0.05f, {7.59, 4.48}}, {512, 0.1f, {22.01, 10.46}}, {512, 0.2f, {77.92, 36.82}},
                {256, 0.05f, {3.47, 2.85}}, {256, 0.1f, {6.39, 4.12}}, {256, 0.2f, {20.04, 10.55}}},
               true});
  t.push_back({4, "without vs with shared memory (hash grid, radius, hybrid); ours: cell-sorted",
               {{"no shared memory", grid, radius, hybrid},
                {"shared memory (Alg. 1)", grid, radius, DensityKernel::SharedMemory},
                {"cell-sorted (ours)", grid, radius, DensityKernel::CellSorted}},
               {{512, 0.05f, {4.63, 4.95}}, {512, 0.1f, {11.86, 10.57}}, {512, 0.2f, {34.76, 32.01}},
                {256, 0.05f, {2.82, 2.79}}, {256, 0.1f, {4.12, 4.25}}, {256, 0.2f, {10.52, 9.30}}},
               true});
  return t;
}

// The scene's rig, at --eye-size if given.
StereoRig benchRig(const Scene& scene, const FrameBenchArgs& args) {
  StereoRig rig = scene.rig;
  if (args.eyeSize.empty()) return rig;
  int w = 0, h = 0;
  if (std::sscanf(args.eyeSize.c_str(), "%dx%d", &w, &h) != 2 || w < 1 || h < 1 || w > 8192 || h > 8192)
    throw Error("--eye-size must be WxH between 1x1 and 8192x8192, got '" + args.eyeSize + "'");
  rig.width = w, rig.height = h;
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

struct CellResult {
  double frameMs = 0, traceMs = 0, buildMs = 0, raysMs = 0, densityMs = 0;
  size_t stored = 0, deviceBytes = 0, mapBytes = 0;
  FrameResult last;  ///< a frame with images, for the checks
};

CellResult timeCell(FrameRenderer& renderer, const StereoRig& rig, const RenderOptions& o, int warmup, int frames) {
  CellResult r;
  for (int i = 0; i < warmup; ++i) renderer.render(rig, o, false);
  for (int i = 0; i < frames; ++i) {
    auto start = Clock::now();
    FrameResult f = renderer.render(rig, o, false);
    r.frameMs += msSince(start);
    r.traceMs += f.timings.photonTraceMs;
    r.buildMs += f.timings.mapBuildMs;
    r.raysMs += f.timings.eyeRayMs[0] + f.timings.eyeRayMs[1];
    r.densityMs += f.timings.densityMs[0] + f.timings.densityMs[1];
    r.stored = f.storedPhotons;
    r.deviceBytes = std::max(r.deviceBytes, f.deviceBytes);
    r.mapBytes = f.mapBytes;
  }
  double n = std::max(frames, 1);
  r.frameMs /= n, r.traceMs /= n, r.buildMs /= n, r.raysMs /= n, r.densityMs /= n;
  r.last = renderer.render(rig, o, true);
  return r;
}

RenderOptions tableOptions(const Row& row, const Variant& v, int k) {
  RenderOptions o;
  o.photonsX = o.photonsY = row.photons;
  o.map = v.map;
  o.kernel = v.kernel;
  o.gather.mode = ShadingMode::PhotonMapOnly;  // the paper's formulation
  o.gather.density.radius = row.radius;
  o.gather.density.estimator = v.estimator;
  o.gather.density.k = k;
  return o;
}

int runTables(const FrameBenchArgs& args, const Scene& scene, FrameRenderer& renderer, const StereoRig& rig,
              nlohmann::json& json) {
  int failures = 0;
  std::vector<int> wanted;
  for (const std::string& t : splitList(args.tables)) {
    if (t != "1" && t != "2" && t != "3" && t != "4") throw Error("--tables takes numbers 1 to 4, got '" + t + "'");
    wanted.push_back(std::stoi(t));
  }
  std::printf("\nPaper tables on %s (%s backend): scene %s, both eyes %dx%d, photon-map-only shading (the paper's), "
              "kNN k=%d, %d frames averaged after %d warm-up frames.\n"
              "Frame = wall time of one stereo frame (photon trace + map build + both eyes), synchronized; stages "
              "by CUDA events. Paper = RTX 2060 SUPER, one view.\n",
              renderer.deviceName().c_str(), renderer.name().c_str(), scene.name.c_str(), rig.width, rig.height, args.k,
              args.frames, args.warmup);
  for (const Table& table : paperTables()) {
    if (std::find(wanted.begin(), wanted.end(), table.number) == wanted.end()) continue;
    std::printf("\nTable %d: %s\n\n| photons | radius |", table.number, table.title.c_str());
    for (const Variant& v : table.variants) std::printf(" %s ms |", v.name.c_str());
    for (size_t c = 0; c < 2; ++c) std::printf(" paper %s ms |", table.variants[c].name.c_str());
    std::printf(" check |\n|---|---|");
    for (size_t c = 0; c < table.variants.size() + 3; ++c) std::printf("---|");
    std::printf("\n");
    std::string details;
    for (const Row& row : table.rows) {
      std::vector<CellResult> cells;
      for (const Variant& v : table.variants)
        cells.push_back(timeCell(renderer, rig, tableOptions(row, v, args.k), args.warmup, args.frames));
      std::string check = "ok";
      double worst = 0;
      if (table.sameImage) {
        for (size_t c = 1; c < cells.size(); ++c)
          for (int e = 0; e < 2; ++e) {
            ImageDiff d = compareImages(cells[0].last.eyes[e].image, cells[c].last.eyes[e].image);
            worst = std::max(worst, d.relativeMad);
            if (d.relativeMad > 0.005 || d.outlierFraction > 0.002) check = "MISMATCH";
          }
      }
      if (check != "ok") ++failures;
      std::printf("| %ux%u | %g |", row.photons, row.photons, row.radius);
      for (const CellResult& c : cells) std::printf(" %.2f |", c.frameMs);
      for (double p : row.paperMs) std::printf(" %.2f |", p);
      if (table.sameImage) std::printf(" %s (%.1e) |\n", check.c_str(), worst);
      else std::printf(" n/a |\n");
      for (size_t c = 0; c < cells.size(); ++c) {
        const CellResult& r = cells[c];
        char line[512];
        std::snprintf(line, sizeof line,
                      "| %ux%u | %g | %s | %.2f | %.3f | %.3f | %.2f | %.2f | %zu | %.1f | %.1f |\n", row.photons,
                      row.photons, row.radius, table.variants[c].name.c_str(), r.frameMs, r.traceMs, r.buildMs,
                      r.raysMs, r.densityMs, r.stored, r.mapBytes / 1048576.0, r.deviceBytes / 1048576.0);
        details += line;
        json.push_back({{"table", table.number}, {"photons", row.photons * row.photons}, {"photons_grid", row.photons},
                        {"radius", row.radius}, {"variant", table.variants[c].name}, {"frame_ms", r.frameMs},
                        {"trace_ms", r.traceMs}, {"build_ms", r.buildMs}, {"eye_rays_ms", r.raysMs},
                        {"density_ms", r.densityMs}, {"stored_photons", r.stored}, {"map_bytes", r.mapBytes},
                        {"device_bytes", r.deviceBytes},
                        {"paper_ms", c < row.paperMs.size() ? nlohmann::json(row.paperMs[c]) : nlohmann::json()},
                        {"check", table.sameImage ? check : "n/a"}});
      }
      std::fflush(stdout);
    }
    std::printf("\nTable %d per stage (ms per stereo frame; eye rays and density summed over both eyes):\n\n"
                "| photons | radius | variant | frame | trace | build | eye rays | density | stored | map MiB | GPU MiB |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|\n%s",
                table.number, details.c_str());
  }
  return failures;
}

#ifdef PVR_HAVE_CUDA
int runRays(const FrameBenchArgs& args, nlohmann::json& json) {
  int failures = 0;
  std::printf("\nRay throughput of the CUDA traversal (binary BVH from Embree, SAH + spatial splits; watertight "
              "triangles), both eyes, one ray per pixel, median of 20 runs\n\n"
              "| scene | triangles | BVH nodes | refs | build ms | eye size | primary Mrays/s | shadow Mrays/s | "
              "diffuse Mrays/s | check vs Embree |\n|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& name : splitList(args.raysScene)) {
    Scene scene = loadScene(name);
    StereoRig rig = benchRig(scene, args);
    CudaFrameRenderer gpu(scene);
    GpuRayThroughput t = gpu.measureRays(rig, 20);
    // Check: the left eye's pixel-centre hits against Embree on the CPU, every 13th pixel.
    CpuBackend cpu(scene);
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
    const BvhBuildStats& s = gpu.bvhStats();
    auto mrays = [](uint64_t rays, double ms) { return ms > 0 ? double(rays) / (ms * 1e3) : 0.0; };
    std::printf("| %s | %u | %u | %u | %.0f | %dx%d x2 | %.0f | %.0f | %.0f | %s (%.4f%% agree) |\n", name.c_str(),
                s.inputTriangles, s.nodes, s.triangleReferences, s.buildMs, rig.width, rig.height,
                mrays(t.primaryRays, t.primaryMs), mrays(t.shadowRays, t.shadowMs), mrays(t.diffuseRays, t.diffuseMs),
                ok ? "ok" : "MISMATCH", 100.0 * agreement);
    json.push_back({{"suite", "rays"}, {"scene", name}, {"triangles", s.inputTriangles}, {"bvh_nodes", s.nodes},
                    {"bvh_refs", s.triangleReferences}, {"bvh_build_ms", s.buildMs}, {"sah_cost", s.sahCost},
                    {"width", rig.width}, {"height", rig.height}, {"primary_rays", t.primaryRays},
                    {"primary_ms", t.primaryMs}, {"shadow_rays", t.shadowRays}, {"shadow_ms", t.shadowMs},
                    {"diffuse_rays", t.diffuseRays}, {"diffuse_ms", t.diffuseMs},
                    {"primary_mrays_s", mrays(t.primaryRays, t.primaryMs)},
                    {"shadow_mrays_s", mrays(t.shadowRays, t.shadowMs)},
                    {"diffuse_mrays_s", mrays(t.diffuseRays, t.diffuseMs)}, {"check_agreement", agreement}});
    std::fflush(stdout);
  }
  return failures;
}

int runGrid(const FrameBenchArgs& args, nlohmann::json& json) {
  Scene scene = loadScene(args.scene);
  CudaFrameRenderer gpu(scene);
  PhotonTraceParams params;
  params.photonCount = 1u << 20;
  params.storeDirect = true;
  std::vector<Photon> photons = gpu.tracePhotons(params);
  photons.resize(std::min<size_t>(photons.size(), 1u << 20));
  int failures = 0;
  std::printf("\nHash-grid build on the GPU: %zu photons traced in %s; keys, CUB radix sort of (cell, index), "
              "startIdx by scan, photons gathered; median of 50 builds (CUDA events)\n\n"
              "| photons | radius | cells | GPU build ms | CPU build ms | check vs CPU |\n|---|---|---|---|---|---|\n",
              photons.size(), scene.name.c_str());
  for (float radius : {0.02f, 0.05f, 0.1f, 0.2f}) {
    GpuHashGridCopy copy;
    double ms = gpu.buildHashGrid(photons, radius, 50, &copy);
    auto start = Clock::now();
    HashGrid cpu = HashGrid::build(photons, radius);
    double cpuMs = msSince(start);
    bool ok = copy.cellStart == cpu.cellStart() && copy.sortedToInput == cpu.sortedToInput();
    failures += ok ? 0 : 1;
    std::printf("| %zu | %g | %zu | %.3f | %.1f | %s |\n", photons.size(), radius, cpu.cellStart().size() - 1, ms,
                cpuMs, ok ? "ok (identical)" : "MISMATCH");
    json.push_back({{"suite", "grid"}, {"photons", photons.size()}, {"radius", radius},
                    {"cells", cpu.cellStart().size() - 1}, {"gpu_build_ms", ms}, {"cpu_build_ms", cpuMs},
                    {"check", ok ? "ok" : "MISMATCH"}});
  }
  return failures;
}
#endif

}  // namespace

int runFrameBench(const FrameBenchArgs& args) {
  if (args.suite != "tables" && args.suite != "rays" && args.suite != "grid" && args.suite != "all")
    throw Error("--suite must be tables, rays, grid or all, got '" + args.suite + "'");
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
  if (args.suite == "tables" || args.suite == "all") {
    Scene scene = loadScene(args.scene);
    StereoRig rig = benchRig(scene, args);
    std::unique_ptr<FrameRenderer> renderer = makeFrameRenderer(kind, scene);
    failures += runTables(args, scene, *renderer, rig, json);
  }
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
