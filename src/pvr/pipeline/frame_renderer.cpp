#include "pvr/pipeline/frame_renderer.h"

#include <algorithm>

namespace pvr {

const char* stageName(Stage stage) {
  switch (stage) {
    case Stage::PhotonTrace: return "photon trace";
    case Stage::MapBuild: return "map build";
    case Stage::Scatter: return "stereo scatter";
    case Stage::EyeRays: return "eye rays";
    case Stage::Density: return "density estimation";
    case Stage::Reconstruct: return "foveated reconstruction";
    case Stage::Temporal: return "temporal resolve";
    case Stage::Count: break;
  }
  return "?";
}

const char* frameDataName(FrameData data) {
  switch (data) {
    case FrameData::Photons: return "photons";
    case FrameData::PhotonMap: return "photon map";
    case FrameData::SourceSurfaces: return "source surfaces";
    case FrameData::ScatteredSurfaces: return "scattered surfaces";
    case FrameData::RenderedImage: return "rendered image";
    case FrameData::InverseDepth: return "inverse depth";
    case FrameData::FirstHits: return "first hits";
    case FrameData::SampleSpacing: return "sample spacing";
    case FrameData::ReusedFrom: return "reuse map";
    case FrameData::DisplayedImage: return "displayed image";
    case FrameData::Count: break;
  }
  return "?";
}

StageIO photonTraceIO() { return {Stage::PhotonTrace, {}, {{FrameData::Photons}}}; }
StageIO mapBuildIO() { return {Stage::MapBuild, {{FrameData::Photons}}, {{FrameData::PhotonMap}}}; }
StageIO scatterIO() { return {Stage::Scatter, {{FrameData::SourceSurfaces}}, {{FrameData::ScatteredSurfaces}}}; }

StageIO eyePassIO(const EyePass& pass) {
  const int e = int(pass.eye);
  StageIO io{Stage::EyeRays, {{FrameData::PhotonMap}}, {{FrameData::RenderedImage, e}, {FrameData::InverseDepth, e}}};
  io.writes.push_back({pass.foveated() ? FrameData::SampleSpacing : FrameData::FirstHits, e});
  if (pass.role == StereoRole::Source) io.writes.push_back({FrameData::SourceSurfaces});
  if (pass.role == StereoRole::Reuser) {
    io.reads.push_back({FrameData::SourceSurfaces});
    io.reads.push_back({FrameData::RenderedImage, int(Eye::Left)});
    if (pass.reuse == StereoMode::Scatter) io.reads.push_back({FrameData::ScatteredSurfaces});
    if (!pass.foveated()) io.writes.push_back({FrameData::ReusedFrom, e});
  }
  return io;
}

StageIO temporalIO(Eye eye, bool foveated) {
  const int e = int(eye);
  StageIO io{Stage::Temporal, {{FrameData::RenderedImage, e}, {FrameData::InverseDepth, e}}, {{FrameData::DisplayedImage, e}}};
  if (foveated) io.reads.push_back({FrameData::SampleSpacing, e});
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

FrameRenderer::FrameRenderer(std::unique_ptr<FrameBackend> backend) : backend_(std::move(backend)) {
  if (!backend_) throw Error("a frame renderer needs a backend");
}

void FrameRenderer::resetHistory() {
  for (Eye e : {Eye::Left, Eye::Right}) backend_->forgetHistory(e);
}

const Vec3* FrameRenderer::deviceImage(Eye eye) const {
  return rendered_[int(eye)] ? backend_->deviceImage(eye, displayed_[int(eye)]) : nullptr;
}

const float* FrameRenderer::deviceInverseDepth(Eye eye) const {
  return rendered_[int(eye)] ? backend_->deviceInverseDepth(eye) : nullptr;
}

FrameResult FrameRenderer::render(const StereoRig& rig, const RenderOptions& options, bool images) {
  validateOptions(options, rig);
  rendered_[0] = rendered_[1] = false;
  FrameBackend& backend = *backend_;
  StageClock& clock = backend.clock();
  clock.newFrame();
  FrameDataflow flow;
  FrameResult frame;

  flow.run(photonTraceIO());
  {
    StageScope scope(clock, Stage::PhotonTrace);
    frame.storedPhotons = backend.tracePhotons(options.photonTraceParams());
  }
  flow.run(mapBuildIO());
  {
    StageScope scope(clock, Stage::MapBuild);
    frame.mapBytes = backend.buildPhotonMap(options.map, options.gather.density.radius);
  }

  const bool reusing = options.stereo != StereoMode::Separate;
  const FoveationMask* mask = options.foveation.mask;
  FoveationOptions foveation = options.foveation;  // the right eye's gaze may follow the left's
  for (Eye eye : {Eye::Left, Eye::Right}) {
    const int e = int(eye);
    if (!options.eyes[e]) {
      backend.forgetHistory(eye);  // its history would be stale when it comes back
      continue;
    }
    EyePass pass;
    pass.eye = eye;
    pass.camera = rig.eye(eye);
    pass.gather = options.gather;
    pass.map = options.map;
    pass.kernel = options.kernel;
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
    if (!options.temporal.enabled) {
      backend.forgetHistory(eye);
      continue;
    }
    flow.run(temporalIO(eye, pass.foveated()));
    StageScope scope(clock, Stage::Temporal, e);
    backend.resolveTemporal(eye, pass.camera, options.temporal.taa, pass.foveated());
  }

  const FrameCounters counters = backend.finishFrame();
  for (int e = 0; e < 2; ++e) {
    rendered_[e] = options.eyes[e];
    displayed_[e] = flow.has(FrameData::DisplayedImage, e);
  }
  frame.reusedPixels = counters.reusedSamples;
  frame.deviceBytes = counters.deviceBytes;
  StageTimings& t = frame.timings;
  t.photonTraceMs = clock.ms(Stage::PhotonTrace, kWholeFrame);
  t.mapBuildMs = clock.ms(Stage::MapBuild, kWholeFrame);
  t.scatterMs = clock.ms(Stage::Scatter, int(Eye::Right));
  for (int e = 0; e < 2; ++e) {
    if (!options.eyes[e]) continue;
    frame.shadedSamples[e] = counters.shadedSamples[e];
    frame.historyPixels[e] = counters.historyPixels[e];
    t.eyeRayMs[e] = clock.ms(Stage::EyeRays, e);
    t.densityMs[e] = clock.ms(Stage::Density, e);
    t.reconstructMs[e] = clock.ms(Stage::Reconstruct, e);
    t.temporalMs[e] = clock.ms(Stage::Temporal, e);
    t.eyeMs[e] = t.eyeRayMs[e] + t.densityMs[e] + t.reconstructMs[e] + t.temporalMs[e] + clock.ms(Stage::Scatter, e);
  }
  if (!images) return frame;
  for (Eye eye : {Eye::Left, Eye::Right}) {
    const int e = int(eye);
    if (!options.eyes[e]) continue;
    EyeReadback what;
    what.displayed = flow.has(FrameData::DisplayedImage, e);
    what.firstPrim = flow.has(FrameData::FirstHits, e);
    what.sampleSpacing = flow.has(FrameData::SampleSpacing, e);
    what.reusedFrom = flow.has(FrameData::ReusedFrom, e);
    backend.readEye(eye, what, frame.eyes[e]);
  }
  return frame;
}

}  // namespace pvr
