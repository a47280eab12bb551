#include "pvr/cpu/cpu_renderer.h"

#include <tbb/info.h>

#include <chrono>
#include <fstream>
#include <string>

namespace pvr {
namespace {

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

std::string CpuFrameRenderer::deviceName() const {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line, model = "CPU";
  while (std::getline(cpuinfo, line))
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  return model + ", " + std::to_string(tbb::info::default_concurrency()) + " threads";
}

FrameResult renderFrame(const CpuBackend& backend, const StereoRig& rig, const RenderOptions& options) {
  validateOptions(options, rig);
  FrameResult frame;
  PhotonTraceParams traceParams = options.photonTraceParams();

  auto start = std::chrono::steady_clock::now();
  std::vector<Photon> photons = backend.tracePhotons(traceParams);
  frame.timings.photonTraceMs = msSince(start);
  frame.storedPhotons = photons.size();

  start = std::chrono::steady_clock::now();
  HashGrid grid;
  KdTree tree;
  if (options.map == PhotonMapKind::HashGrid) {
    grid = HashGrid::build(photons, options.gather.density.radius);
    frame.mapBytes = grid.memoryBytes();
  } else {
    tree = KdTree::build(photons);
    frame.mapBytes = tree.memoryBytes();
  }
  frame.timings.mapBuildMs = msSince(start);

  for (int e = 0; e < 2; ++e) {
    if (!options.eyes[e]) continue;
    EyeCamera camera = rig.eye(Eye(e));
    std::vector<PixelSample> samples(size_t(camera.width) * camera.height);
    start = std::chrono::steady_clock::now();
    if (options.map == PhotonMapKind::HashGrid)
      backend.renderEye(camera, Eye(e), options.gather, grid.view(), samples.data());
    else
      backend.renderEye(camera, Eye(e), options.gather, tree.view(), samples.data());
    frame.timings.eyeMs[e] = msSince(start);
    frame.timings.eyeRayMs[e] = frame.timings.eyeMs[e];  // one fused pass, like the single kernel
    EyeResult& out = frame.eyes[e];
    out.image = Image(camera.width, camera.height);
    out.firstPrim.resize(samples.size());
    for (size_t i = 0; i < samples.size(); ++i) {
      out.image.pixels[i] = samples[i].radiance;
      out.firstPrim[i] = samples[i].firstPrim;
    }
  }
  return frame;
}

}  // namespace pvr
