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

  const FoveationMask* mask = options.foveation.mask;
  if (mask) checkMaskFits(*mask, rig.width, rig.height);
  FoveationOptions foveation = options.foveation;  // the right eye's gaze may follow the left's
  // The left eye first: under stereo reuse the right eye reads its surfaces and finished image.
  const bool reusing = options.stereo != StereoMode::Separate;
  std::vector<PixelSample> samples;
  std::vector<SurfaceRecord> leftSurfaces;
  std::vector<uint64_t> scattered;
  for (int e = 0; e < 2; ++e) {
    if (!options.eyes[e]) continue;
    EyeCamera camera = rig.eye(Eye(e));
    const size_t pixels = size_t(camera.width) * camera.height;
    EyeResult& out = frame.eyes[e];
    StereoReuseView reuse;
    if (reusing && e == 0) leftSurfaces.assign(pixels, SurfaceRecord());  // foveated: only vertices' pixels are written
    if (reusing && e == 1) {
      reuse.mode = options.stereo;
      reuse.source = rig.eye(Eye::Left);
      reuse.sourceSurfaces = leftSurfaces.data();
      reuse.sourceImage = frame.eyes[0].image.pixels.data();
    }
    SurfaceRecord* surfaces = reusing && e == 0 ? leftSurfaces.data() : nullptr;
    start = std::chrono::steady_clock::now();
    if (reuse.mode == StereoMode::Scatter) {
      scattered.resize(pixels);
      backend.scatter(leftSurfaces.data(), leftSurfaces.size(), camera, scattered.data());
      reuse.scattered = scattered.data();
      frame.timings.scatterMs = msSince(start);
    }
    if (mask) {
      auto eyeStart = std::chrono::steady_clock::now();
      if (e == 1 && foveation.verge)
        vergeRightGaze(rig, foveation,
                       options.eyes[0] ? &frame.eyes[0].inverseDepth[foveation.gazePixelIndex(0, rig.width, rig.height)]
                                       : nullptr);
      std::copy(foveation.gaze[e], foveation.gaze[e] + 2, frame.gaze[e]);
      int gx, gy;
      foveation.gazePixel(e, rig.width, rig.height, gx, gy);
      size_t reused = 0;
      frame.shadedSamples[e] =
          options.map == PhotonMapKind::HashGrid
              ? backend.renderFoveatedEye(camera, Eye(e), options.gather, grid.view(), *mask, gx, gy, out, reuse,
                                          surfaces, &reused)
              : backend.renderFoveatedEye(camera, Eye(e), options.gather, tree.view(), *mask, gx, gy, out, reuse,
                                          surfaces, &reused);
      frame.reusedPixels += reused;
      frame.timings.eyeRayMs[e] = msSince(eyeStart);
      frame.timings.eyeMs[e] = msSince(start);
      continue;
    }
    samples.assign(pixels, PixelSample());
    auto eyeStart = std::chrono::steady_clock::now();
    if (options.map == PhotonMapKind::HashGrid)
      backend.renderEye(camera, Eye(e), options.gather, grid.view(), samples.data(), reuse, surfaces);
    else
      backend.renderEye(camera, Eye(e), options.gather, tree.view(), samples.data(), reuse, surfaces);
    frame.timings.eyeRayMs[e] = msSince(eyeStart);  // one fused pass, like the single kernel
    frame.timings.eyeMs[e] = msSince(start);
    frame.shadedSamples[e] = samples.size();
    out.image = Image(camera.width, camera.height);
    out.firstPrim.resize(samples.size());
    out.inverseDepth.resize(samples.size());
    for (size_t i = 0; i < samples.size(); ++i) {
      out.image.pixels[i] = samples[i].radiance;
      out.firstPrim[i] = samples[i].firstPrim;
      out.inverseDepth[i] = samples[i].inverseDepth;
    }
    if (reuse.reusing()) {
      out.reusedFrom.resize(samples.size());
      for (size_t i = 0; i < samples.size(); ++i) {
        out.reusedFrom[i] = samples[i].reusedFrom;
        frame.reusedPixels += out.reusedFrom[i] != kNotReused ? 1 : 0;
      }
    }
  }
  return frame;
}

FrameResult CpuFrameRenderer::render(const StereoRig& rig, const RenderOptions& options, bool images) {
  FrameResult frame = renderFrame(backend_, rig, options);
  for (int e = 0; e < 2; ++e) {
    if (!options.eyes[e] || !options.temporal.enabled) {  // a skipped eye's history would be stale
      history_[e].valid = false;
      continue;
    }
    auto start = std::chrono::steady_clock::now();
    frame.historyPixels[e] = resolveTemporal(rig.eye(Eye(e)), options.temporal.taa, frame.eyes[e], history_[e]);
    frame.timings.temporalMs[e] = msSince(start);
    frame.timings.eyeMs[e] += frame.timings.temporalMs[e];
  }
  return frame;
}

}  // namespace pvr
