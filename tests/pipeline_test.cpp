// The frame pipeline written once: its stage order over any backend, the dataflow its stages
// declare, the results it returns (present exactly when a stage wrote them), option validation in
// one place, and labelled parallel loops.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <string>
#include <vector>

#include "pvr/app/options.h"
#include "pvr/cpu/cpu_frame_backend.h"
#include "pvr/foveation/mask.h"
#include "pvr/scene/scene.h"
#include "pvr/util/parallel_for.h"

namespace pvr {
namespace {

// A backend that does no work and records the stages it was asked to run, in order.
class RecordingBackend : public FrameBackend {
 public:
  std::vector<std::string> calls;
  std::string name() const override { return "recording"; }
  std::string deviceName() const override { return "none"; }
  StageClock& clock() override { return clock_; }
  size_t tracePhotons(const PhotonTraceParams&, int, int) override { return record("trace"), 0; }
  size_t buildPhotonMap(PhotonMapKind, float) override { return record("build"), 0; }
  void rasterizePrimary(const EyeCamera*) override { record("raster"); }
  void scatter(const EyeCamera&, const EyeCamera&) override { record("scatter"); }
  void renderEye(const EyePass& pass) override {
    static const char* roles[] = {"alone", "source", "reuser"};
    record(std::string("eye ") + (pass.eye == Eye::Left ? "left " : "right ") + roles[int(pass.role)] +
           (pass.foveated() ? " foveated" : "") + (pass.rasterPrimary ? " from raster" : ""));
  }
  float inverseDepthAt(Eye eye, size_t) override { return record(eye == Eye::Left ? "depth left" : "depth right"), 0.0f; }
  void denoise(const EyePass& pass, const DenoiseParams&) override {
    record(pass.eye == Eye::Left ? "denoise left" : "denoise right");
  }
  void resolveTemporal(const TemporalPass& pass) override {
    record(std::string(pass.eye == Eye::Left ? "taa left" : "taa right") + (pass.denoised ? " of denoised" : ""));
  }
  void forgetHistory(Eye eye) override { record(eye == Eye::Left ? "forget left" : "forget right"); }
  void forgetDenoiseHistory(Eye) override {}
  FrameCounters finishFrame() override { return record("finish"), FrameCounters(); }
  void readEye(Eye eye, const EyeReadback& what, EyeResult& out) override {
    record(std::string("read ") + (eye == Eye::Left ? "left" : "right"));
    if (what.firstPrim) out.firstPrim.emplace();
    if (what.sampleSpacing) out.sampleSpacing.emplace();
    if (what.reusedFrom) out.reusedFrom.emplace();
    displayed[int(eye)] = what.image == EyeImage::Displayed;
    denoised[int(eye)] = what.image == EyeImage::Denoised;
  }
  bool displayed[2] = {false, false}, denoised[2] = {false, false};

 private:
  void record(const std::string& call) { calls.push_back(call); }
  HostStageClock clock_;
};

std::string joined(const std::vector<std::string>& calls) {
  std::string s;
  for (const std::string& c : calls) s += (s.empty() ? "" : ", ") + c;
  return s;
}

StereoRig tinyRig() {
  StereoRig rig;
  rig.width = 32, rig.height = 36;
  return rig;
}

TEST(FramePipeline, TheRasterPrePassRunsOnceBeforeBothEyesThatReadIt) {
  auto backend = std::make_unique<RecordingBackend>();
  RecordingBackend& r = *backend;
  FrameRenderer renderer(std::move(backend));
  RenderOptions o;
  o.primary = PrimaryVisibility::Raster;
  o.stereo = StereoMode::Gather;
  renderer.render(tinyRig(), o);
  EXPECT_EQ(joined(r.calls), "trace, build, raster, eye left source from raster, forget left, "
                             "eye right reuser from raster, forget right, finish, read left, read right");
}

TEST(FramePipeline, RunsTheStagesInOneOrder) {
  auto backend = std::make_unique<RecordingBackend>();
  RecordingBackend& r = *backend;
  FrameRenderer renderer(std::move(backend));
  RenderOptions o;
  renderer.render(tinyRig(), o);
  EXPECT_EQ(joined(r.calls), "trace, build, eye left alone, forget left, eye right alone, forget right, finish, "
                             "read left, read right");

  r.calls.clear();
  o.stereo = StereoMode::Scatter;
  o.temporal.enabled = true;
  renderer.render(tinyRig(), o);
  EXPECT_EQ(joined(r.calls), "trace, build, eye left source, taa left, scatter, eye right reuser, taa right, finish, "
                             "read left, read right");
  EXPECT_TRUE(r.displayed[0] && r.displayed[1]);

  r.calls.clear();
  o.denoise.enabled = true;
  renderer.render(tinyRig(), o);
  EXPECT_EQ(joined(r.calls), "trace, build, eye left source, denoise left, taa left of denoised, scatter, eye right reuser, "
                             "denoise right, taa right of denoised, finish, read left, read right");
  o.temporal.enabled = false;
  r.calls.clear();
  renderer.render(tinyRig(), o);
  EXPECT_TRUE(r.denoised[0] && r.denoised[1]);
  o.denoise.enabled = false;

  r.calls.clear();
  FoveationMask mask = generateFoveationMask(maskParamsForRig(tinyRig()));
  o.foveation.mask = &mask;
  o.foveation.verge = true;
  o.stereo = StereoMode::Gather;
  o.temporal.enabled = false;
  renderer.render(tinyRig(), o, false);
  EXPECT_EQ(joined(r.calls), "trace, build, eye left source foveated, forget left, depth left, "
                             "eye right reuser foveated, forget right, finish");

  r.calls.clear();
  o = RenderOptions();
  o.eyes[0] = false;
  renderer.render(tinyRig(), o);
  EXPECT_EQ(joined(r.calls), "trace, build, forget left, eye right alone, forget right, finish, read right");
}

// Below gi nothing gathers photons: after the first frame (whose map makes the buffers) no
// photons are traced and no map is built; back at gi, every slice of a rolling map is traced again.
TEST(FramePipeline, FramesWithNothingAtGiTraceNoPhotons) {
  auto backend = std::make_unique<RecordingBackend>();
  RecordingBackend& r = *backend;
  Material wall, mirror;
  mirror.type = MaterialType::Mirror;
  mirror.effectGroup = 1;
  FrameRenderer renderer(std::move(backend), {wall, mirror});
  RenderOptions o;
  o.photonBatches = 2;
  o.gather.overrideEffects = true;
  o.gather.effects = EffectLevel::Shadows;
  renderer.render(tinyRig(), o, false);
  EXPECT_EQ(joined(r.calls), "trace, trace, build, eye left alone, forget left, eye right alone, forget right, finish");
  for (EffectLevel level : {EffectLevel::Raster, EffectLevel::Shadows, EffectLevel::Reflections, EffectLevel::Path}) {
    r.calls.clear();
    o.gather.effects = level;
    renderer.render(tinyRig(), o, false);
    EXPECT_EQ(joined(r.calls), "eye left alone, forget left, eye right alone, forget right, finish") << effectLevelName(level);
  }
  // One group (the mirror's) at gi: photons again, all slices (not the rolling one).
  o.gather.overrideEffects = false;
  o.gather.groupEffects[0] = uint8_t(EffectLevel::Shadows);
  o.gather.groupEffects[1] = uint8_t(EffectLevel::Gi);
  r.calls.clear();
  renderer.render(tinyRig(), o, false);
  EXPECT_EQ(joined(r.calls), "trace, trace, build, eye left alone, forget left, eye right alone, forget right, finish");
  r.calls.clear();
  renderer.render(tinyRig(), o, false);
  EXPECT_EQ(joined(r.calls), "trace, build, eye left alone, forget left, eye right alone, forget right, finish");
}

// On the CPU backend a frame at shadows after a gi frame of other photons is the frame a fresh
// renderer makes: the stale map is not read.
TEST(FramePipeline, AFrameBelowGiDoesNotReadTheLastMap) {
  Scene scene = builtinScene("cornell");
  StereoRig rig = tinyRig();
  RenderOptions gi;
  gi.photonsX = gi.photonsY = 24;
  RenderOptions shadows;
  shadows.photonsX = shadows.photonsY = 64;
  shadows.gather.overrideEffects = true;
  shadows.gather.effects = EffectLevel::Shadows;
  FrameRenderer fresh = makeCpuFrameRenderer(scene);
  const FrameResult expected = fresh.render(rig, shadows);
  FrameRenderer used = makeCpuFrameRenderer(scene);
  used.render(rig, gi);
  const FrameResult f = used.render(rig, shadows);
  EXPECT_EQ(f.storedPhotons, 0u);
  EXPECT_EQ(f.timings.photonTraceMs, 0.0);
  EXPECT_EQ(f.timings.mapBuildMs, 0.0);
  for (int e = 0; e < 2; ++e) {
    const std::vector<Vec3>&a = f.eyes[e].image.pixels, &b = expected.eyes[e].image.pixels;
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i)
      ASSERT_TRUE(a[i].x == b[i].x && a[i].y == b[i].y && a[i].z == b[i].z) << "eye " << e << " pixel " << i;
  }
}

// Each eye's outputs are present exactly when a stage of the frame wrote them.
TEST(FramePipeline, ResultsHoldWhatTheStagesWrote) {
  FoveationMask mask = generateFoveationMask(maskParamsForRig(tinyRig()));
  for (StereoMode stereo : {StereoMode::Separate, StereoMode::Scatter, StereoMode::Gather})
    for (bool foveated : {false, true}) {
      auto backend = std::make_unique<RecordingBackend>();
      FrameRenderer renderer(std::move(backend));
      RenderOptions o;
      o.stereo = stereo;
      o.foveation.mask = foveated ? &mask : nullptr;
      FrameResult f = renderer.render(tinyRig(), o);
      const std::string what = std::string(stereoModeName(stereo)) + (foveated ? " foveated" : "");
      for (int e = 0; e < 2; ++e) {
        EXPECT_EQ(f.eyes[e].firstPrim.has_value(), !foveated) << what;
        EXPECT_EQ(f.eyes[e].sampleSpacing.has_value(), foveated) << what;
      }
      EXPECT_FALSE(f.eyes[0].reusedFrom.has_value()) << what;
      EXPECT_EQ(f.eyes[1].reusedFrom.has_value(), stereo != StereoMode::Separate && !foveated) << what;
    }
}

TEST(FramePipeline, AStageThatReadsWhatNoStageWroteIsAnError) {
  FrameDataflow flow;
  EyePass right;
  right.eye = Eye::Right;
  right.role = StereoRole::Reuser;
  right.reuse = StereoMode::Gather;
  EXPECT_THROW(flow.run(eyePassIO(right)), Error) << "no photon map yet";
  flow.run(photonTraceIO());
  flow.run(mapBuildIO());
  try {
    flow.run(eyePassIO(right));
    FAIL() << "the right eye reused a left eye that was never rendered";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("source surfaces"), std::string::npos) << e.what();
  }
  EyePass left;
  left.role = StereoRole::Source;
  flow.run(eyePassIO(left));
  flow.run(eyePassIO(right));
  EXPECT_TRUE(flow.has(FrameData::ReusedFrom, 1));
  EXPECT_FALSE(flow.has(FrameData::DisplayedImage, 1));
  auto resolve = [](bool foveated, bool denoised, bool emittedApart) {
    TemporalPass t;
    t.eye = Eye::Right;
    t.foveated = foveated, t.denoised = denoised, t.emittedApart = emittedApart, t.reuser = emittedApart;
    return t;
  };
  EXPECT_THROW(flow.run(temporalIO(resolve(true, false, false))), Error) << "a full-resolution eye has no sample spacing";
  EXPECT_THROW(flow.run(temporalIO(resolve(false, true, false))), Error) << "nothing denoised the right eye";
  EXPECT_THROW(flow.run(temporalIO(resolve(false, false, true))), Error) << "the eye passes wrote no guides";
  EXPECT_THROW(flow.run(denoiseIO(right)), Error) << "the eye passes wrote no denoise guides";
  flow.run(temporalIO(resolve(false, false, false)));
  EXPECT_TRUE(flow.has(FrameData::DisplayedImage, 1));
}

// The right eye's denoise under reuse reads the left eye's denoised image: the left must be
// denoised first.
TEST(FramePipeline, TheReusersDenoiseReadsTheLeftEyesDenoisedImage) {
  FrameDataflow flow;
  flow.run(photonTraceIO());
  flow.run(mapBuildIO());
  EyePass left, right;
  left.role = StereoRole::Source, left.denoiseGuides = true;
  right.eye = Eye::Right, right.role = StereoRole::Reuser, right.reuse = StereoMode::Gather, right.denoiseGuides = true;
  flow.run(eyePassIO(left));
  flow.run(eyePassIO(right));
  EXPECT_TRUE(flow.has(FrameData::DenoiseGuides, 0) && flow.has(FrameData::DenoiseGuides, 1));
  try {
    flow.run(denoiseIO(right));
    FAIL() << "the right eye's denoise ran before the left's";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("denoised image of the left eye"), std::string::npos) << e.what();
  }
  flow.run(denoiseIO(left));
  flow.run(denoiseIO(right));
  EXPECT_TRUE(flow.has(FrameData::DenoisedImage, 1));
}

// The CPU backend's timings: each eye's time is the sum of its stages, and only stages that ran count.
TEST(FramePipeline, EyeTimeIsTheSumOfItsStages) {
  Scene scene = builtinScene("cornell");
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  StereoRig rig = tinyRig();
  RenderOptions o;
  o.photonsX = o.photonsY = 32;
  o.stereo = StereoMode::Scatter;
  o.temporal.enabled = true;
  FrameResult f = renderer.render(rig, o);
  const StageTimings& t = f.timings;
  EXPECT_GT(t.photonTraceMs, 0.0);
  EXPECT_GT(t.scatterMs, 0.0);
  for (int e = 0; e < 2; ++e) {
    EXPECT_GT(t.eyeRayMs[e], 0.0);
    EXPECT_GT(t.temporalMs[e], 0.0);
    EXPECT_EQ(t.reconstructMs[e], 0.0) << "not foveated";
    EXPECT_DOUBLE_EQ(t.eyeMs[e], t.eyeRayMs[e] + t.densityMs[e] + t.temporalMs[e] + (e == 1 ? t.scatterMs : 0.0));
  }
  EXPECT_EQ(f.shadedSamples[0], size_t(rig.width) * rig.height);
}

TEST(FrameOptions, ErrorsNameTheOptionAndTheCommandLineItsFlag) {
  StereoRig rig = tinyRig();
  struct Case {
    RenderOption option;
    void (*spoil)(RenderOptions&, StereoRig&);
    const char* flag;
  };
  const Case cases[] = {
      {RenderOption::Photons, [](RenderOptions& o, StereoRig&) { o.photonsX = 0; }, "--photons"},
      {RenderOption::Photons, [](RenderOptions& o, StereoRig&) { o.photonsX = 8193, o.photonsY = 8192; }, "--photons"},
      {RenderOption::Radius, [](RenderOptions& o, StereoRig&) { o.gather.density.radius = -1; }, "--radius"},
      {RenderOption::K, [](RenderOptions& o, StereoRig&) { o.gather.density.estimator = Estimator::Knn, o.gather.density.k = 0; }, "--k"},
      {RenderOption::SamplesPerPixel, [](RenderOptions& o, StereoRig&) { o.gather.samplesPerPixel = 0; }, "--spp"},
      {RenderOption::EyeSize, [](RenderOptions&, StereoRig& r) { r.width = 9000; }, "--eye-size"},
      {RenderOption::Ipd, [](RenderOptions&, StereoRig& r) { r.ipd = -0.01f; }, "--ipd"},
      {RenderOption::Kernel, [](RenderOptions& o, StereoRig&) { o.kernel = DensityKernel::SharedMemory, o.map = PhotonMapKind::KdTree; }, "--kernel"},
      {RenderOption::Gaze, [](RenderOptions& o, StereoRig&) { o.foveation.gaze[1][0] = 1.5f; }, "--gaze"},
      {RenderOption::TaaBlend, [](RenderOptions& o, StereoRig&) { o.temporal.enabled = true, o.temporal.taa.blend = 0; }, "--taa-blend"},
      {RenderOption::Stereo, [](RenderOptions& o, StereoRig&) { o.stereo = StereoMode::Gather, o.eyes[1] = false; }, "--stereo"},
      {RenderOption::DenoiseIterations, [](RenderOptions& o, StereoRig&) { o.denoise.enabled = true, o.denoise.params.iterations = 9; }, "--denoise-iterations"},
      {RenderOption::DenoiseDirectIterations, [](RenderOptions& o, StereoRig&) { o.denoise.enabled = true, o.denoise.params.directIterations = 0; }, "--denoise-direct-iterations"},
      {RenderOption::DenoiseParameter, [](RenderOptions& o, StereoRig&) { o.denoise.enabled = true, o.denoise.params.colourAlpha = 0; }, "--denoise"},
      {RenderOption::DenoiseParameter, [](RenderOptions& o, StereoRig&) { o.denoise.enabled = true, o.denoise.params.depthTolerance = NAN; }, "--denoise"},
      {RenderOption::DenoiseParameter, [](RenderOptions& o, StereoRig&) { o.denoise.enabled = true, o.denoise.params.refineAlpha = 1; }, "--denoise"},
  };
  EXPECT_NO_THROW(validateOptions(RenderOptions(), rig));
  for (const Case& c : cases) {
    RenderOptions o;
    StereoRig r = rig;
    c.spoil(o, r);
    try {
      validateOptions(o, r);
      ADD_FAILURE() << c.flag << ": accepted";
    } catch (const OptionError& e) {
      EXPECT_EQ(e.option(), c.option) << e.what();
      EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << "the library speaks its own words: " << e.what();
      EXPECT_EQ(describeForCli(e).rfind(std::string(c.flag) + ": ", 0), 0u) << describeForCli(e);
    }
  }
  // The renderer checks them too, before any stage runs.
  auto backend = std::make_unique<RecordingBackend>();
  RecordingBackend& recorded = *backend;
  FrameRenderer renderer(std::move(backend));
  RenderOptions bad;
  bad.gather.density.radius = 0;
  EXPECT_THROW(renderer.render(rig, bad), OptionError);
  EXPECT_TRUE(recorded.calls.empty());
}

TEST(ParallelFor, CoversEveryItemOnceAndNamesItsWorkInErrors) {
  std::vector<std::atomic<int>> seen(10007);
  parallelFor("count", seen.size(), 64, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) ++seen[i];
  });
  for (const auto& s : seen) ASSERT_EQ(s.load(), 1);
  std::vector<std::atomic<int>> pixels(37 * 53);
  parallelForTiles("tiles", 37, 53, 16, [&](int y0, int y1, int x0, int x1) {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) ++pixels[size_t(y) * 53 + x];
  });
  for (const auto& p : pixels) ASSERT_EQ(p.load(), 1);
  try {
    parallelFor("photon trace", 100, 1, [](size_t begin, size_t) {
      if (begin == 42) throw Error("a non-finite photon");
    });
    FAIL() << "the error was lost";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "photon trace: a non-finite photon");
  }
}

}  // namespace
}  // namespace pvr
