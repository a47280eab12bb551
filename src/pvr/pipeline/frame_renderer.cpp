#include "pvr/pipeline/frame_renderer.h"

#include <algorithm>
#include <cmath>

namespace pvr {

const char* stageName(Stage stage) {
  switch (stage) {
    case Stage::PhotonTrace: return "photon trace";
    case Stage::MapBuild: return "map build";
    case Stage::Scatter: return "stereo scatter";
    case Stage::EyeRays: return "eye rays";
    case Stage::Density: return "density estimation";
    case Stage::Reconstruct: return "foveated reconstruction";
    case Stage::Denoise: return "denoise";
    case Stage::Temporal: return "temporal resolve";
    case Stage::Primary: return "raster pre-pass";
    case Stage::Count: break;
  }
  return "?";
}

const char* frameDataName(FrameData data) {
  switch (data) {
    case FrameData::Photons: return "photons";
    case FrameData::PhotonMap: return "photon map";
    case FrameData::PrimaryHits: return "rasterised first hits";
    case FrameData::SourceSurfaces: return "source surfaces";
    case FrameData::ScatteredSurfaces: return "scattered surfaces";
    case FrameData::RenderedImage: return "rendered image";
    case FrameData::InverseDepth: return "inverse depth";
    case FrameData::FirstHits: return "first hits";
    case FrameData::SampleSpacing: return "sample spacing";
    case FrameData::ReusedFrom: return "reuse map";
    case FrameData::DenoiseGuides: return "denoise guides";
    case FrameData::DenoisedImage: return "denoised image";
    case FrameData::DisplayedImage: return "displayed image";
    case FrameData::Count: break;
  }
  return "?";
}

StageIO photonTraceIO() { return {Stage::PhotonTrace, {}, {{FrameData::Photons}}}; }
StageIO primaryIO(const bool eyes[2]) {
  StageIO io{Stage::Primary, {}, {}};
  for (int e = 0; e < 2; ++e)
    if (eyes[e]) io.writes.push_back({FrameData::PrimaryHits, e});
  return io;
}

StageIO mapBuildIO() { return {Stage::MapBuild, {{FrameData::Photons}}, {{FrameData::PhotonMap}}}; }
StageIO scatterIO() { return {Stage::Scatter, {{FrameData::SourceSurfaces}}, {{FrameData::ScatteredSurfaces}}}; }

StageIO eyePassIO(const EyePass& pass) {
  const int e = int(pass.eye);
  StageIO io{Stage::EyeRays, {{FrameData::PhotonMap}}, {{FrameData::RenderedImage, e}, {FrameData::InverseDepth, e}}};
  io.writes.push_back({pass.foveated() ? FrameData::SampleSpacing : FrameData::FirstHits, e});
  if (pass.rasterPrimary) io.reads.push_back({FrameData::PrimaryHits, e});
  if (pass.role == StereoRole::Source) io.writes.push_back({FrameData::SourceSurfaces});
  if (pass.denoiseGuides && !pass.foveated()) io.writes.push_back({FrameData::DenoiseGuides, e});
  if (pass.role == StereoRole::Reuser) {
    io.reads.push_back({FrameData::SourceSurfaces});
    io.reads.push_back({FrameData::RenderedImage, int(Eye::Left)});
    if (pass.reuse == StereoMode::Scatter) io.reads.push_back({FrameData::ScatteredSurfaces});
    if (!pass.foveated()) io.writes.push_back({FrameData::ReusedFrom, e});
  }
  return io;
}

StageIO denoiseIO(const EyePass& pass) {
  const int e = int(pass.eye);
  StageIO io{Stage::Denoise, {{FrameData::RenderedImage, e}, {FrameData::InverseDepth, e}}, {{FrameData::DenoisedImage, e}}};
  if (pass.foveated()) {
    io.reads.push_back({FrameData::SampleSpacing, e});
    return io;
  }
  io.reads.push_back({FrameData::DenoiseGuides, e});
  if (pass.role == StereoRole::Reuser) {
    const int left = int(Eye::Left);
    io.reads.push_back({FrameData::ReusedFrom, e});
    io.reads.push_back({FrameData::RenderedImage, left});
    io.reads.push_back({FrameData::DenoiseGuides, left});
    io.reads.push_back({FrameData::DenoisedImage, left});
  }
  return io;
}

StageIO temporalIO(const TemporalPass& pass) {
  const int e = int(pass.eye);
  StageIO io{Stage::Temporal,
             {{pass.denoised ? FrameData::DenoisedImage : FrameData::RenderedImage, e}, {FrameData::InverseDepth, e}},
             {{FrameData::DisplayedImage, e}}};
  if (pass.foveated) io.reads.push_back({FrameData::SampleSpacing, e});
  if (pass.emittedApart) io.reads.push_back({FrameData::DenoiseGuides, e});
  if (pass.reuser) {
    io.reads.push_back({FrameData::ReusedFrom, e});
    io.reads.push_back({FrameData::DenoiseGuides, int(Eye::Left)});
  }
  return io;
}

void FrameDataflow::require(const DataRef& r, const char* reader) const {
  if (!has(r.data, r.eye))
    throw Error(std::string("frame pipeline: ") + reader + " reads the " + frameDataName(r.data) +
                (r.eye == kWholeFrame ? "" : r.eye == 0 ? " of the left eye" : " of the right eye") +
                ", which no earlier stage of this frame wrote");
}

void FrameDataflow::run(const StageIO& io) {
  for (const DataRef& r : io.reads) require(r, stageName(io.stage));
  for (const DataRef& w : io.writes) written_[slot(w.data, w.eye)] = true;
}

FrameRenderer::FrameRenderer(std::unique_ptr<FrameBackend> backend, std::vector<Material> materials)
    : backend_(std::move(backend)), materials_(std::move(materials)) {
  if (!backend_) throw Error("a frame renderer needs a backend");
}

namespace {

// Whether two frames' options make the same picture, so that a still head may refine across them.
bool samePicture(const RenderOptions& a, const RenderOptions& b) {
  const GatherParams &ga = a.gather, &gb = b.gather;
  bool same = a.photonsX == b.photonsX && a.photonsY == b.photonsY && a.maxPhotonDepth == b.maxPhotonDepth &&
              a.map == b.map && a.density == b.density && a.cacheCellFraction == b.cacheCellFraction &&
              ga.density.radius == gb.density.radius && ga.density.estimator == gb.density.estimator &&
              ga.density.k == gb.density.k && ga.density.boundary == gb.density.boundary && ga.mode == gb.mode && ga.maxSpecularDepth == gb.maxSpecularDepth &&
              ga.samplesPerPixel == gb.samplesPerPixel && ga.punctualShadowRays == gb.punctualShadowRays &&
              ga.seed == gb.seed && ga.sampling == gb.sampling && a.eyes[0] == b.eyes[0] && a.eyes[1] == b.eyes[1] && a.stereo == b.stereo &&
              a.foveation.mask == b.foveation.mask && a.temporal.enabled == b.temporal.enabled;
  for (int e = 0; e < 2 && same && a.foveation.mask; ++e)
    same = a.foveation.gaze[e][0] == b.foveation.gaze[e][0] && a.foveation.gaze[e][1] == b.foveation.gaze[e][1];
  return same;
}

// Whether any surface's effect level gathers photons (gi); with no materials known, yes.
bool gathersPhotons(const GatherParams& params, const std::vector<Material>& materials) {
  if (materials.empty()) return true;
  return std::any_of(materials.begin(), materials.end(),
                     [&](const Material& m) { return effectLevelOf(params, m) == EffectLevel::Gi; });
}

// Whether two frames' options trace the same photons (a rolling map may keep its slices).
bool samePhotons(const RenderOptions& a, const RenderOptions& b) {
  return a.photonsX == b.photonsX && a.photonsY == b.photonsY && a.maxPhotonDepth == b.maxPhotonDepth &&
         a.gather.mode == b.gather.mode && a.gather.seed == b.gather.seed && a.photonBatches == b.photonBatches;
}

// Whether the head moved less than the tolerances between two rigs of the same eyes.
bool stillView(const StereoRig& a, const StereoRig& b, const DenoiseParams& p) {
  if (a.width != b.width || a.height != b.height || a.ipd != b.ipd) return false;
  for (int e = 0; e < 2; ++e) {
    const Fov &fa = a.fov[e], &fb = b.fov[e];
    if (fa.angleLeft != fb.angleLeft || fa.angleRight != fb.angleRight || fa.angleUp != fb.angleUp ||
        fa.angleDown != fb.angleDown)
      return false;
  }
  const Quat &qa = a.head.orientation, &qb = b.head.orientation;
  const float cosHalf = std::fabs(qa.x * qb.x + qa.y * qb.y + qa.z * qb.z + qa.w * qb.w);
  const float angleDegrees = 2.0f * std::acos(std::fmin(1.0f, cosHalf)) * 180.0f / kPi;
  return length(a.head.position - b.head.position) <= p.stillPosition && angleDegrees <= p.stillAngleDegrees;
}

}  // namespace

void FrameRenderer::resetHistory() {
  lastRig_.reset();
  stillFrames_ = 0;
  for (Eye e : {Eye::Left, Eye::Right}) {
    backend_->forgetHistory(e);
    backend_->forgetDenoiseHistory(e);
  }
}

const Vec3* FrameRenderer::deviceImage(Eye eye) const {
  return rendered_[int(eye)] ? backend_->deviceImage(eye, shown_[int(eye)]) : nullptr;
}

const float* FrameRenderer::deviceInverseDepth(Eye eye) const {
  return rendered_[int(eye)] ? backend_->deviceInverseDepth(eye) : nullptr;
}

FrameResult FrameRenderer::render(const StereoRig& rig, const RenderOptions& requested, bool images) {
  validateOptions(requested, rig);
  RenderOptions options = requested;
  if (requested.temporal.enabled || requested.denoise.enabled) {
    if (freshNoise_) options.gather.sequenceIndex = blendedFrames_;
    ++blendedFrames_;
  }
  // A still head refines: each still frame's photons are gathered with a smaller radius.
  const DenoiseParams& refine = requested.denoise.params;
  const bool still = requested.denoise.enabled && refine.refineWhenStill && lastRig_ &&
                     stillView(rig, *lastRig_, refine) && samePicture(requested, lastOptions_);
  stillFrames_ = still ? stillFrames_ + 1 : 0;
  lastRig_ = rig;
  lastOptions_ = requested;
  if (stillFrames_ > 0) {
    const float first = requested.gather.density.radius;
    options.gather.density.radius =
        std::max(progressiveRadius(first, stillFrames_, refine.refineAlpha), first * refine.minRadiusFraction);
  }
  gatherRadius_ = options.gather.density.radius;
  rendered_[0] = rendered_[1] = false;
  FrameBackend& backend = *backend_;
  StageClock& clock = backend.clock();
  clock.newFrame();
  FrameDataflow flow;
  FrameResult frame;

  // Below gi nothing reads the map: no photons are traced and the last map (or, before the first,
  // a map of this frame's photons, so that its buffers exist) stays unread.
  const bool photons = !mapBuilt_ || gathersPhotons(options.gather, materials_);
  flow.run(photonTraceIO());
  if (photons) {
    StageScope scope(clock, Stage::PhotonTrace);
    // A rolling map retraces one slice a frame; all of them at first, after a change of the
    // photons' options, and while refining (each still frame wants photons of its own).
    const int slots = options.photonBatches;
    const bool refill = !photonsHeld_ || stillFrames_ > 0 || !samePhotons(requested, lastPhotonOptions_);
    const PhotonTraceParams params = options.photonTraceParams();
    auto traceSlot = [&](int k) {
      PhotonTraceParams slice = params;
      slice.firstPhoton = uint32_t(uint64_t(params.photonCount) * uint64_t(k) / uint64_t(slots));
      slice.tracedPhotons = uint32_t(uint64_t(params.photonCount) * uint64_t(k + 1) / uint64_t(slots)) - slice.firstPhoton;
      return backend.tracePhotons(slice, k, slots);
    };
    if (refill) {
      for (int k = 0; k < slots; ++k) frame.storedPhotons = traceSlot(k);
      nextPhotonSlot_ = 0;
    } else {
      frame.storedPhotons = traceSlot(nextPhotonSlot_);
      nextPhotonSlot_ = (nextPhotonSlot_ + 1) % slots;
    }
    photonsHeld_ = true;
    lastPhotonOptions_ = requested;
  } else {
    photonsHeld_ = false;  // the next gi frame traces every slice afresh
  }
  flow.run(mapBuildIO());
  if (photons) {
    StageScope scope(clock, Stage::MapBuild);
    frame.mapBytes = backend.buildPhotonMap(options.map, options.gather.density.radius);
    mapBuilt_ = true;
  }

  const bool raster = options.primary == PrimaryVisibility::Raster;
  if (raster) {
    flow.run(primaryIO(options.eyes));
    const EyeCamera eyes[2] = {rig.eye(Eye::Left), rig.eye(Eye::Right)};
    backend.rasterizePrimary(eyes);
  }
  const bool reusing = options.stereo != StereoMode::Separate;
  const FoveationMask* mask = options.foveation.mask;
  FoveationOptions foveation = options.foveation;  // the right eye's gaze may follow the left's
  for (Eye eye : {Eye::Left, Eye::Right}) {
    const int e = int(eye);
    if (!options.eyes[e]) {
      backend.forgetHistory(eye);  // its histories would be stale when it comes back
      backend.forgetDenoiseHistory(eye);
      continue;
    }
    EyePass pass;
    pass.eye = eye;
    pass.camera = rig.eye(eye);
    pass.gather = options.gather;
    pass.map = options.map;
    pass.kernel = options.kernel;
    pass.density = options.density;
    pass.cacheCellSize = options.cacheCellFraction * options.gather.density.radius;
    // TAA keeps the emitted part out of its history; the denoiser also needs the rest.
    pass.denoiseGuides = options.denoise.enabled || options.temporal.enabled;
    pass.stillFrames = stillFrames_;
    pass.rasterPrimary = raster;
    pass.raySchedule = options.raySchedule;
    pass.role = !reusing ? StereoRole::Alone : eye == Eye::Left ? StereoRole::Source : StereoRole::Reuser;
    if (pass.role == StereoRole::Reuser) {
      pass.reuse = options.stereo;
      pass.source = rig.eye(Eye::Left);
      if (options.stereo == StereoMode::Scatter) {
        flow.run(scatterIO());
        StageScope scope(clock, Stage::Scatter, e);
        backend.scatter(pass.source, pass.camera);
      }
    }
    if (mask) {
      if (eye == Eye::Right && foveation.verge) {
        float leftInverseDepth = 0.0f;
        if (options.eyes[0]) {
          flow.require({FrameData::InverseDepth, int(Eye::Left)}, "vergence");
          leftInverseDepth = backend.inverseDepthAt(Eye::Left, foveation.gazePixelIndex(0, rig.width, rig.height));
        }
        vergeRightGaze(rig, foveation.gaze[0], options.eyes[0] ? &leftInverseDepth : nullptr, foveation.gaze[1]);
      }
      std::copy(foveation.gaze[e], foveation.gaze[e] + 2, frame.gaze[e]);
      pass.mask = mask;
      foveation.gazePixel(e, rig.width, rig.height, pass.gazeX, pass.gazeY);
    }
    flow.run(eyePassIO(pass));
    backend.renderEye(pass);  // times its own parts
    if (options.denoise.enabled) {
      flow.run(denoiseIO(pass));
      StageScope scope(clock, Stage::Denoise, e);
      backend.denoise(pass, options.denoise.params);
    } else {
      backend.forgetDenoiseHistory(eye);
    }
    if (!options.temporal.enabled) {
      backend.forgetHistory(eye);
      continue;
    }
    TemporalPass resolve;
    resolve.eye = eye;
    resolve.camera = pass.camera;
    resolve.params = options.temporal.taa;
    resolve.foveated = pass.foveated();
    resolve.denoised = options.denoise.enabled;
    resolve.emittedApart = pass.denoiseGuides && !pass.foveated();
    resolve.reuser = resolve.emittedApart && pass.role == StereoRole::Reuser;
    flow.run(temporalIO(resolve));
    StageScope scope(clock, Stage::Temporal, e);
    backend.resolveTemporal(resolve);
  }

  const FrameCounters counters = backend.finishFrame();
  for (int e = 0; e < 2; ++e) {
    rendered_[e] = options.eyes[e];
    shown_[e] = flow.has(FrameData::DisplayedImage, e)  ? EyeImage::Displayed
                : flow.has(FrameData::DenoisedImage, e) ? EyeImage::Denoised
                                                        : EyeImage::Rendered;
  }
  frame.reusedPixels = counters.reusedSamples;
  frame.cacheCells = counters.cacheCells;
  frame.cacheUnplaced = counters.cacheUnplaced;
  frame.deviceBytes = counters.deviceBytes;
  StageTimings& t = frame.timings;
  t.photonTraceMs = clock.ms(Stage::PhotonTrace, kWholeFrame);
  t.mapBuildMs = clock.ms(Stage::MapBuild, kWholeFrame);
  t.primaryMs = clock.ms(Stage::Primary, kWholeFrame);
  t.primaryDrawMs = counters.primaryDrawMs;
  t.scatterMs = clock.ms(Stage::Scatter, int(Eye::Right));
  for (int e = 0; e < 2; ++e) {
    if (!options.eyes[e]) continue;
    frame.shadedSamples[e] = counters.shadedSamples[e];
    frame.historyPixels[e] = counters.historyPixels[e];
    t.eyeRayMs[e] = clock.ms(Stage::EyeRays, e);
    t.densityMs[e] = clock.ms(Stage::Density, e);
    t.reconstructMs[e] = clock.ms(Stage::Reconstruct, e);
    t.denoiseMs[e] = clock.ms(Stage::Denoise, e);
    t.temporalMs[e] = clock.ms(Stage::Temporal, e);
    t.eyeMs[e] = t.eyeRayMs[e] + t.densityMs[e] + t.reconstructMs[e] + t.denoiseMs[e] + t.temporalMs[e] +
                 clock.ms(Stage::Scatter, e);
  }
  if (!images) return frame;
  for (Eye eye : {Eye::Left, Eye::Right}) {
    const int e = int(eye);
    if (!options.eyes[e]) continue;
    EyeReadback what;
    what.image = shown_[e];
    what.firstPrim = flow.has(FrameData::FirstHits, e);
    what.sampleSpacing = flow.has(FrameData::SampleSpacing, e);
    what.reusedFrom = flow.has(FrameData::ReusedFrom, e);
    backend.readEye(eye, what, frame.eyes[e]);
  }
  return frame;
}

}  // namespace pvr
