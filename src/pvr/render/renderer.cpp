#include "pvr/render/renderer.h"

#include <chrono>
#include <cmath>
#include <string>

#include "pvr/util/error.h"

namespace pvr {
namespace {

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

constexpr int kMaxEyeDimension = 8192;

}  // namespace

void validateOptions(const RenderOptions& o, const StereoRig& rig) {
  if (o.photonsX == 0 || o.photonsY == 0) throw Error("the number of photons must be positive");
  if (uint64_t(o.photonsX) * o.photonsY > (uint64_t(1) << 26))
    throw Error("too many photons: " + std::to_string(uint64_t(o.photonsX) * o.photonsY) + " (at most 8192x8192)");
  if (o.maxPhotonDepth < 1 || o.maxPhotonDepth > 64) throw Error("the photon depth must be between 1 and 64");
  const DensityParams& d = o.gather.density;
  if (!(d.radius > 0.0f) || !std::isfinite(d.radius)) throw Error("the search radius must be a positive finite number");
  if (d.estimator == Estimator::Knn && (d.k < 1 || d.k > kMaxKnn))
    throw Error("k must be between 1 and " + std::to_string(kMaxKnn));
  if (o.gather.samplesPerPixel < 1 || o.gather.samplesPerPixel > 4096)
    throw Error("samples per pixel must be between 1 and 4096");
  if (o.gather.maxSpecularDepth < 0 || o.gather.maxSpecularDepth > 64)
    throw Error("the specular depth must be between 0 and 64");
  if (rig.width < 1 || rig.height < 1 || rig.width > kMaxEyeDimension || rig.height > kMaxEyeDimension)
    throw Error("the eye size must be between 1x1 and " + std::to_string(kMaxEyeDimension) + "x" +
                std::to_string(kMaxEyeDimension) + ", got " + std::to_string(rig.width) + "x" + std::to_string(rig.height));
  if (!(rig.ipd >= 0.0f) || !std::isfinite(rig.ipd)) throw Error("the IPD must be a non-negative finite number");
}

FrameResult renderFrame(const CpuBackend& backend, const StereoRig& rig, const RenderOptions& options) {
  validateOptions(options, rig);
  FrameResult frame;
  PhotonTraceParams traceParams;
  traceParams.photonCount = options.photonCount();
  traceParams.seed = options.gather.seed;
  traceParams.maxDepth = options.maxPhotonDepth;
  traceParams.storeDirect = options.gather.mode == ShadingMode::PhotonMapOnly;

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
