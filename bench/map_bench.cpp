#include "map_bench.h"

#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "pvr/cpu/cpu_backend.h"
#include "bench_util.h"
#include "pvr/util/latency_stats.h"
#include "pvr/util/error.h"
#include "pvr/util/parallel_for.h"

namespace pvr {
namespace {

struct QueryPoint {
  Vec3 position, normal;
};

// The times of `repeats` runs of f(), in ms: the minimum (the figure the table reports) and the tail.
struct RepeatTimes {
  double min = 0;
  LatencyStats stats;
};

template <class F>
RepeatTimes timeRepeats(int repeats, F&& f) {
  std::vector<double> ms;
  for (int r = 0; r < repeats; ++r) {
    auto start = std::chrono::steady_clock::now();
    f();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  RepeatTimes t;
  t.min = ms.empty() ? 0.0 : *std::min_element(ms.begin(), ms.end());
  t.stats = latencyStats(std::move(ms));
  return t;
}

// A table cell: "min / p99".
std::string minP99(const RepeatTimes& t) {
  char text[64];
  std::snprintf(text, sizeof text, "%.2f / %.2f", t.min, t.stats.p99);
  return text;
}

uint32_t parseGrid(const std::string& s, uint32_t& nx, uint32_t& ny) {
  char x = 0;
  std::stringstream ss(s);
  if (!(ss >> nx >> x >> ny) || (x != 'x' && x != 'X') || nx == 0 || ny == 0 || nx > 8192 || ny > 8192)
    throw Error("expected WxH with positive integers up to 8192, got '" + s + "'");
  return nx * ny;
}

std::string cpuName() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown CPU";
}

// First hits of the left eye's pixel-centre rays on a coarse grid: realistic query points.
std::vector<QueryPoint> eyeHitPoints(const CpuBackend& backend, const StereoRig& rig, uint32_t w, uint32_t h) {
  EyeCamera cam = rig.eye(Eye::Left);
  SceneView view = backend.scene().view();
  std::vector<QueryPoint> points;
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      Ray ray = cam.generateRay((x + 0.5f) * cam.width / w, (y + 0.5f) * cam.height / h);
      Hit hit;
      if (!backend.intersector().intersect(ray, INFINITY, hit)) continue;
      SurfacePoint sp = view.surfacePoint(hit);
      if (view.materials[sp.materialId].isSpecular()) continue;
      points.push_back({sp.position, dot(ray.dir, sp.geometricNormal) < 0 ? sp.geometricNormal : -sp.geometricNormal});
    }
  return points;
}

template <class Map>
void estimateAll(const Map& map, const std::vector<QueryPoint>& q, const DensityParams& p, std::vector<Vec3>& out) {
  parallelFor("map queries", q.size(), 64, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) out[i] = estimateFluxDensity(map, q[i].position, q[i].normal, p);
  });
}

// Largest relative difference between two estimate sets, relative to the mean magnitude.
double maxRelativeDifference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double mean = 0, worst = 0;
  for (const Vec3& v : a) mean += luminance(v);
  mean = std::max(mean / std::max<size_t>(a.size(), 1), 1e-30);
  for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, double(maxComponent(max(a[i] - b[i], b[i] - a[i]))));
  return worst / mean;
}

}  // namespace

int runMapBench(const MapBenchArgs& args) {
  if (args.k < 1 || args.k > kMaxKnn) throw Error("--k must be between 1 and " + std::to_string(kMaxKnn));
  if (args.repeats < 1 || args.repeats > 1000) throw Error("--repeats must be between 1 and 1000");
  uint32_t qw, qh;
  parseGrid(args.queries, qw, qh);
  std::vector<float> radii;
  for (const std::string& r : splitList(args.radii)) {
    char* end = nullptr;
    float v = std::strtof(r.c_str(), &end);
    if (*end != '\0' || !(v > 0.0f) || !std::isfinite(v)) throw Error("radii must be positive numbers, got '" + r + "'");
    radii.push_back(v);
  }
  std::vector<std::pair<uint32_t, uint32_t>> grids;
  for (const std::string& g : splitList(args.photons)) {
    uint32_t nx, ny;
    parseGrid(g, nx, ny);
    grids.push_back({nx, ny});
  }

  Scene scene = loadScene(args.scene);
  CpuBackend backend(scene);
  std::vector<QueryPoint> queries = eyeHitPoints(backend, scene.rig, qw, qh);
  int threads = tbb::info::default_concurrency();
  std::printf("photon-map benchmark, CPU backend: %s, %d threads\n", cpuName().c_str(), threads);
  std::printf("scene %s; %zu query points (diffuse first hits of the left eye on a %ux%u grid); kNN k=%d; "
              "minimum / p99 of %d runs (p99 by nearest rank: the max under 100 runs; mean, p50, p99 and max in the "
              "JSON)\n\n",
              scene.name.c_str(), queries.size(), qw, qh, args.k, args.repeats);
  std::printf("| photons | stored | radius | kd build ms (min / p99) | grid build ms (min / p99) | kd radius ms (min / "
              "p99) | grid radius ms (min / p99) | kd kNN ms (min / p99) | grid kNN ms (min / p99) | photons/query | "
              "check |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");

  nlohmann::json results = nlohmann::json::array();
  bool allOk = true;
  for (auto [nx, ny] : grids) {
    PhotonTraceParams tp;
    tp.photonCount = nx * ny;
    tp.storeDirect = true;  // the paper's map holds every photon
    std::vector<Photon> photons = backend.tracePhotons(tp);
    KdTree tree;
    RepeatTimes kdBuild = timeRepeats(args.repeats, [&] { tree = KdTree::build(photons); });
    for (float radius : radii) {
      HashGrid grid;
      RepeatTimes gridBuild = timeRepeats(args.repeats, [&] { grid = HashGrid::build(photons, radius); });
      DensityParams radiusSum{radius, Estimator::Radius, args.k};
      DensityParams knn{radius, Estimator::Knn, args.k};
      std::vector<Vec3> kdR(queries.size()), gridR(queries.size()), kdK(queries.size()), gridK(queries.size());
      RepeatTimes kdRadius = timeRepeats(args.repeats, [&] { estimateAll(tree.view(), queries, radiusSum, kdR); });
      RepeatTimes gridRadius = timeRepeats(args.repeats, [&] { estimateAll(grid.view(), queries, radiusSum, gridR); });
      RepeatTimes kdKnn = timeRepeats(args.repeats, [&] { estimateAll(tree.view(), queries, knn, kdK); });
      RepeatTimes gridKnn = timeRepeats(args.repeats, [&] { estimateAll(grid.view(), queries, knn, gridK); });
      // Self-check: the two maps find the same photons, so the estimates agree up to the order of
      // the float additions.
      double diffRadius = maxRelativeDifference(kdR, gridR), diffKnn = maxRelativeDifference(kdK, gridK);
      bool ok = diffRadius < 1e-4 && diffKnn < 1e-4;
      allOk = allOk && ok;
      double found = 0;
      HashGridView gv = grid.view();
      for (const QueryPoint& q : queries) {
        float r2 = radius * radius;
        gv.search(q.position, r2, [&](uint32_t, float, float&) { found += 1; });
      }
      found /= std::max<size_t>(queries.size(), 1);
      std::printf("| %ux%u | %zu | %.3g | %s | %s | %s | %s | %s | %s | %.0f | %s |\n", nx, ny, photons.size(), radius,
                  minP99(kdBuild).c_str(), minP99(gridBuild).c_str(), minP99(kdRadius).c_str(),
                  minP99(gridRadius).c_str(), minP99(kdKnn).c_str(), minP99(gridKnn).c_str(), found,
                  ok ? "ok" : "MISMATCH");
      std::fflush(stdout);
      results.push_back({{"photons", std::to_string(nx) + "x" + std::to_string(ny)},
                         {"stored_photons", photons.size()},
                         {"radius", radius},
                         {"kd_build_ms", kdBuild.min},
                         {"grid_build_ms", gridBuild.min},
                         {"kd_radius_query_ms", kdRadius.min},
                         {"grid_radius_query_ms", gridRadius.min},
                         {"kd_knn_query_ms", kdKnn.min},
                         {"grid_knn_query_ms", gridKnn.min},
                         {"kd_build", kdBuild.stats},  // mean, p50, p99, max of the runs (the *_ms: their minimum)
                         {"grid_build", gridBuild.stats},
                         {"kd_radius_query", kdRadius.stats},
                         {"grid_radius_query", gridRadius.stats},
                         {"kd_knn_query", kdKnn.stats},
                         {"grid_knn_query", gridKnn.stats},
                         {"photons_in_radius_per_query", found},
                         {"max_relative_difference_radius", diffRadius},
                         {"max_relative_difference_knn", diffKnn},
                         {"check", ok}});
    }
  }
  if (!args.json.empty()) {
    nlohmann::json doc = {{"benchmark", "photon maps (CPU)"},
                          {"cpu", cpuName()},
                          {"threads", threads},
                          {"scene", scene.name},
                          {"query_points", queries.size()},
                          {"query_grid", args.queries},
                          {"k", args.k},
                          {"repeats", args.repeats},
                          {"results", results}};
    std::ofstream out(args.json);
    if (!out) throw Error("cannot write '" + args.json + "'");
    out << doc.dump(2) << "\n";
    std::printf("\nwrote %s\n", args.json.c_str());
  }
  if (!allOk) std::fprintf(stderr, "photonvr: error: the kd-tree and the hash grid disagree (see the check column)\n");
  return allOk ? 0 : 1;
}

}  // namespace pvr
