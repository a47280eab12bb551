#include "pvr/cpu/cpu_frame_backend.h"

#include <tbb/info.h>

#include <fstream>
#include <string>

#include "pvr/raster/gbuffer_raster.h"

namespace pvr {

CpuFrameBackend::CpuFrameBackend(const Scene& scene) : backend_(scene) {}
CpuFrameBackend::~CpuFrameBackend() = default;  // the pre-pass before its Vulkan device

void CpuFrameBackend::rasterizePrimary(const EyeCamera eyes[2]) {
  StageScope scope(clock_, Stage::Primary);  // the host waits for it: its time is the frame's
  if (!raster_) {
    try {
      rasterVulkan_ = std::make_unique<VulkanContext>(VulkanContextOptions());
    } catch (const Error& e) {
      throw Error(std::string("--primary raster: ") + e.what());
    }
    raster_ = std::make_unique<GBufferRaster>(*rasterVulkan_, backend_.scene(), false);
  }
  raster_->render(eyes);
  raster_->waitDone();
  raster_->lastGpuMs(&counters_.primaryDrawMs);
  rasterised_ = true;
}

std::string CpuFrameBackend::deviceName() const {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line, model = "CPU";
  while (std::getline(cpuinfo, line))
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  return model + ", " + std::to_string(tbb::info::default_concurrency()) + " threads";
}

size_t CpuFrameBackend::tracePhotons(const PhotonTraceParams& params, int slot, int slots) {
  if (slots == 1) {
    photonSlots_.clear();
    photons_ = backend_.tracePhotons(params);
    return photons_.size();
  }
  if (int(photonSlots_.size()) != slots) photonSlots_.assign(size_t(slots), {});
  photonSlots_[size_t(slot)] = backend_.tracePhotons(params);
  photons_.clear();
  for (const std::vector<Photon>& s : photonSlots_) photons_.insert(photons_.end(), s.begin(), s.end());
  return photons_.size();
}

size_t CpuFrameBackend::buildPhotonMap(PhotonMapKind kind, float radius) {
  mapKind_ = kind;
  if (!cacheStale_) lastCacheCells_ = cache_.cells();
  cacheStale_ = true;
  if (kind == PhotonMapKind::HashGrid) {
    grid_ = HashGrid::build(photons_, radius);
    return grid_.memoryBytes();
  }
  tree_ = KdTree::build(photons_);
  return tree_.memoryBytes();
}

void CpuFrameBackend::scatter(const EyeCamera& /*source: the records hold world positions*/, const EyeCamera& target) {
  scattered_.resize(size_t(target.width) * target.height);
  backend_.scatter(sourceSurfaces_.data(), sourceSurfaces_.size(), target, scattered_.data());
}

template <class Map>
void CpuFrameBackend::renderEyeWith(const EyePass& pass, const Map& map) {
  const int e = int(pass.eye);
  const EyeCamera& camera = pass.camera;
  const size_t pixels = size_t(camera.width) * camera.height;
  EyeBuffers& out = eyes_[e];
  SurfaceRecord* surfaces = nullptr;
  if (pass.role == StereoRole::Source) {
    sourceSurfaces_.assign(pixels, SurfaceRecord());  // foveated: only the vertices' pixels are written
    surfaces = sourceSurfaces_.data();
  }
  const StereoReuseView reuse =
      reuseViewFor(pass, sourceSurfaces_.data(), eyes_[int(Eye::Left)].rendered.pixels.data(), scattered_.data());

  if (pass.foveated()) {
    std::vector<Vec3> colours;
    std::vector<float> inverseDepths;
    size_t reused = 0;
    {
      StageScope scope(clock_, Stage::EyeRays, e);  // eye rays and estimates in one pass
      counters_.shadedSamples[e] = backend_.shadeMaskVertices(camera, pass.eye, pass.gather, map, *pass.mask, pass.gazeX,
                                                              pass.gazeY, colours, inverseDepths, reuse, surfaces, &reused);
    }
    StageScope scope(clock_, Stage::Reconstruct, e);
    FoveatedImage image;
    reconstructFoveatedEye(*pass.mask, pass.gazeX, pass.gazeY, colours, inverseDepths, image);
    out.rendered = std::move(image.image);
    out.inverseDepth = std::move(image.inverseDepth);
    out.sampleSpacing = std::move(image.sampleSpacing);
    if (pass.role == StereoRole::Reuser) counters_.reusedSamples += reused;
    return;
  }
  samples_.assign(pixels, PixelSample());
  if (pass.denoiseGuides) guides_.assign(pixels, PixelGuide());
  if (pass.density == DensityScheme::SurfaceCache) {
    if (cacheStale_) {  // room for both eyes' points of every sample
      cache_.reset(pass.cacheCellSize, surfaceCacheCapacity(2 * pixels * size_t(pass.gather.samplesPerPixel), lastCacheCells_));
      cacheStale_ = false;
    }
    StageScope scope(clock_, Stage::EyeRays, e);  // eye rays, the cache and its look-ups in one stage
    backend_.renderEyeCached(camera, pass.eye, pass.gather, map, cache_, samples_.data(), reuse, surfaces,
                             pass.denoiseGuides ? guides_.data() : nullptr);
    counters_.cacheCells = cache_.cells();
    counters_.cacheUnplaced = cache_.unplacedPoints();
  } else {
    StageScope scope(clock_, Stage::EyeRays, e);  // one fused pass, like the single kernel
    backend_.renderEye(camera, pass.eye, pass.gather, map, samples_.data(), reuse, surfaces,
                       pass.denoiseGuides ? guides_.data() : nullptr);
  }
  if (pass.denoiseGuides) {
    out.emitted.resize(pixels), out.direct.resize(pixels), out.albedo.resize(pixels), out.normal.resize(pixels);
    for (size_t i = 0; i < pixels; ++i) {
      const PixelGuide& g = guides_[i];
      out.emitted[i] = g.emitted, out.direct[i] = g.direct, out.albedo[i] = g.albedo, out.normal[i] = g.normal;
    }
  }
  counters_.shadedSamples[e] = pixels;
  out.rendered = Image(camera.width, camera.height);
  out.firstPrim.resize(pixels);
  out.inverseDepth.resize(pixels);
  for (size_t i = 0; i < pixels; ++i) {
    out.rendered.pixels[i] = samples_[i].radiance;
    out.firstPrim[i] = samples_[i].firstPrim;
    out.inverseDepth[i] = samples_[i].inverseDepth;
  }
  if (pass.role == StereoRole::Reuser) {
    out.reusedFrom.resize(pixels);
    for (size_t i = 0; i < pixels; ++i) {
      out.reusedFrom[i] = samples_[i].reusedFrom;
      counters_.reusedSamples += out.reusedFrom[i] != kNotReused ? 1 : 0;
    }
  }
}

void CpuFrameBackend::renderEye(const EyePass& pass) {
  EyePass p = pass;
  if (pass.rasterPrimary) {
    if (!rasterised_) throw Error("frame pipeline: an eye pass reads rasterised first hits this frame did not make");
    p.gather.primary = raster_->hostView(pass.eye);
  }
  if (mapKind_ == PhotonMapKind::HashGrid) renderEyeWith(p, grid_.view());
  else renderEyeWith(p, tree_.view());
}

void CpuFrameBackend::denoise(const EyePass& pass, const DenoiseParams& params) {
  EyeBuffers& b = eyes_[int(pass.eye)];
  DenoiseInputs in;
  in.image = b.rendered.pixels.data();
  in.inverseDepth = b.inverseDepth.data();
  if (pass.foveated()) {
    in.sampleSpacing = b.sampleSpacing.data();
  } else {
    in.emitted = b.emitted.data(), in.direct = b.direct.data(), in.albedo = b.albedo.data(), in.normal = b.normal.data();
    in.keepLevels = pass.role == StereoRole::Source;
    if (pass.role == StereoRole::Reuser) {
      const EyeBuffers& left = eyes_[int(Eye::Left)];
      in.reusedFrom = b.reusedFrom.data();
      in.sourceNormal = left.normal.data();
      in.sourceDenoised = left.denoised.pixels.data();
    }
  }
  denoiser_.denoise(pass.eye, pass.camera, params, in, b.denoised, pass.stillFrames);
}

void CpuFrameBackend::resolveTemporal(const TemporalPass& pass) {
  EyeBuffers& b = eyes_[int(pass.eye)];
  TaaEmitted emission;
  if (pass.emittedApart) {
    emission.emitted = b.emitted.data();
    if (pass.reuser) emission.reusedFrom = b.reusedFrom.data(), emission.sourceEmitted = eyes_[int(Eye::Left)].emitted.data();
  }
  counters_.historyPixels[int(pass.eye)] =
      pvr::resolveTemporal(pass.camera, pass.params, pass.denoised ? b.denoised : b.rendered, b.inverseDepth,
                           pass.foveated ? b.sampleSpacing.data() : nullptr, history_[int(pass.eye)], b.displayed, emission);
}

FrameCounters CpuFrameBackend::finishFrame() {
  FrameCounters done = counters_;  // the CPU's stages finished as they returned
  counters_ = FrameCounters();
  rasterised_ = false;
  return done;
}

void CpuFrameBackend::readEye(Eye eye, const EyeReadback& what, EyeResult& out) {
  EyeBuffers& b = eyes_[int(eye)];  // the frame is over: its buffers move out
  out.image = std::move(what.image == EyeImage::Displayed  ? b.displayed
                        : what.image == EyeImage::Denoised ? b.denoised
                                                           : b.rendered);
  out.inverseDepth = std::move(b.inverseDepth);
  if (what.firstPrim) out.firstPrim = std::move(b.firstPrim);
  if (what.sampleSpacing) out.sampleSpacing = std::move(b.sampleSpacing);
  if (what.reusedFrom) out.reusedFrom = std::move(b.reusedFrom);
}

}  // namespace pvr
