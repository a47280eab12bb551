// The budget controller's logic on cost traces, without a GPU: a trace gives each frame's unit
// costs (what the view costs at the reference setting), a frame's time is those costs times the
// chosen setting's scales plus the trace's noise, and the controller sees each frame's measured
// stage times one frame late, as in the loop. Deterministic: the traces are seeded.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "pvr/control/budget_controller.h"
#include "pvr/foveation/mask.h"
#include "pvr/util/latency_stats.h"
#include "pvr/util/rng.h"
#include "pvr/util/error.h"

namespace pvr {
namespace {

constexpr double kFrameMs = 1000.0 / 90.0;

// One frame of a trace: the view's costs at the reference setting, and a multiplicative noise.
struct TraceFrame {
  ControlCosts units;
  double noise = 1.0;
};

// A walk through a scene: a base view, and from frame `heavyFrom` a view `heavy` times as costly,
// reached over `ramp` frames (a head turning towards it), left the same way at `heavyTo`.
std::vector<TraceFrame> walkTrace(int frames, int heavyFrom, int heavyTo, double heavy, int ramp, double noise, uint32_t seed) {
  std::vector<TraceFrame> trace;
  CounterRng rng(seed, 0, 0);
  for (int f = 0; f < frames; ++f) {
    double t = 0;
    if (f >= heavyFrom && f < heavyTo) t = std::min(1.0, double(f - heavyFrom + 1) / ramp);
    if (f >= heavyTo) t = std::max(0.0, 1.0 - double(f - heavyTo + 1) / ramp);
    const double k = 1.0 + (heavy - 1.0) * t;
    TraceFrame tf;
    tf.units.photonMs = 12.0;  // at the top photon count; they cost what they cost wherever the head looks
    tf.units.densityMs = 4.0 * k;
    tf.units.rayMs = 6.0 * k;
    tf.units.denoiseMs = 0.3;
    tf.units.restMs = 0.5;
    tf.noise = 1.0 + noise * (2.0 * rng.uniform() - 1.0);
    trace.push_back(tf);
  }
  return trace;
}

// What a frame at setting s costs on the trace's frame (the plant).
ControlCosts frameCosts(const BudgetController& c, const ControlSetting& s, const TraceFrame& f) {
  const ControlCosts scale = c.scaleOf(s);
  ControlCosts out;
  out.photonMs = f.units.photonMs * scale.photonMs * f.noise;
  out.densityMs = f.units.densityMs * scale.densityMs * f.noise;
  out.rayMs = f.units.rayMs * scale.rayMs * f.noise;
  out.denoiseMs = f.units.denoiseMs * scale.denoiseMs * f.noise;
  out.restMs = f.units.restMs * scale.restMs * f.noise;
  return out;
}

struct SimRun {
  std::vector<double> ms, error;
  int raises = 0, lowers = 0;
  std::vector<double> raiseTimes;
  double p99() const { return latencyStats(ms).p99; }
  double over(double budget) const {
    return double(std::count_if(ms.begin(), ms.end(), [&](double m) { return m > budget; })) / double(ms.size());
  }
  double meanError() const {
    double s = 0;
    for (double e : error) s += e;
    return s / double(error.size());
  }
};

// `plant`: what the frames really cost (default: the model the controller starts with; the
// controller measures its foveated ratio again and must not move the plant with it).
SimRun simulate(BudgetController& c, const std::vector<TraceFrame>& trace, const BudgetController* plant = nullptr) {
  const BudgetController start = c;
  const BudgetController& truth = plant ? *plant : start;
  SimRun run;
  for (size_t f = 0; f < trace.size(); ++f) {
    const double now = double(f) * kFrameMs;
    const ControlDecision d = c.decide(now);
    if (std::string(d.change) == "raise") ++run.raises, run.raiseTimes.push_back(now);
    if (std::string(d.change) == "lower" || std::string(d.change) == "replan") ++run.lowers;
    const ControlCosts costs = frameCosts(truth, d.setting, trace[f]);
    run.ms.push_back(costs.total());
    run.error.push_back(c.predictError(d.setting));
    c.observe(costs);
  }
  return run;
}

// A fixed setting over the same trace.
SimRun simulateFixed(const BudgetController& c, const ControlSetting& s, const std::vector<TraceFrame>& trace) {
  SimRun run;
  for (const TraceFrame& f : trace) run.ms.push_back(frameCosts(c, s, f).total()), run.error.push_back(c.predictError(s));
  return run;
}

std::vector<ControlSetting> everySetting(const ControlProfile& p, bool foveation) {
  std::vector<ControlSetting> out;
  const int groups = int(p.groups.size());
  const int levelCombos = int(std::pow(kControlledLevels, groups));
  for (int ph = 0; ph < int(p.photonSides.size()); ++ph)
    for (int r = 0; r < int(p.radiusScales.size()); ++r)
      for (int d = 0; d < int(p.denoiseIterations.size()); ++d)
        for (int fv = 0; fv < (foveation ? 2 : 1); ++fv)
          for (int l = 0; l < levelCombos; ++l) {
            ControlSetting s;
            s.photons = ph, s.radius = r, s.denoise = d, s.foveated = fv != 0;
            for (int g = 0, rest = l; g < groups; ++g, rest /= kControlledLevels) s.levels[size_t(g)] = uint8_t(rest % kControlledLevels);
            out.push_back(s);
          }
  return out;
}

ControlProfile twoGroups() { return ControlProfile::generic({"rest", "floor"}); }

BudgetControllerParams paramsFor(double budget) {
  BudgetControllerParams p;
  p.budgetMs = budget;
  p.foveationAvailable = true;
  return p;
}

const FoveationMask kMask;  // never rendered: the controller only hands its address on

TEST(BudgetController, HoldsTheBudgetThroughViewsThatCostThreeTimesIt) {
  for (double budget : {kFrameMs, 5.5}) {
    BudgetController c(twoGroups(), paramsFor(budget), RenderOptions(), &kMask);
    // At the best setting the base view costs about the budget's 2.3x (11.1 ms) or 4.7x (5.5 ms); the
    // heavy view three times the base.
    const std::vector<TraceFrame> trace = walkTrace(2700, 900, 1800, 3.0, 45, 0.04, 7);
    const double bestMs = frameCosts(c, c.best(), trace[0]).total();
    EXPECT_GT(bestMs, 2.0 * budget);
    const SimRun run = simulate(c, trace);
    EXPECT_LE(run.p99(), budget) << "budget " << budget;
    EXPECT_LE(run.over(budget), 0.005) << "budget " << budget;
    EXPECT_GT(run.raises, 0) << "it must climb back when the heavy view is left";
  }
}

TEST(BudgetController, LosesLessQualityThanAnyFixedSettingThatMeetsTheBudget) {
  const std::vector<TraceFrame> trace = walkTrace(2700, 900, 1800, 3.0, 45, 0.04, 11);
  for (double budget : {kFrameMs, 5.5}) {
    BudgetController c(twoGroups(), paramsFor(budget), RenderOptions(), &kMask);
    const SimRun controlled = simulate(c, trace);
    BudgetController model(twoGroups(), paramsFor(budget), RenderOptions(), &kMask);
    int meeting = 0;
    double bestFixed = 1e30;
    for (const ControlSetting& s : everySetting(model.profile(), true)) {
      const SimRun fixed = simulateFixed(model, s, trace);
      if (fixed.p99() > budget) continue;
      ++meeting;
      bestFixed = std::min(bestFixed, fixed.meanError());
    }
    ASSERT_GT(meeting, 0);
    EXPECT_LT(controlled.meanError(), bestFixed) << "budget " << budget << ": " << meeting << " fixed settings meet it";
  }
}

TEST(BudgetController, DoesNotOscillateOnASteadyView) {
  BudgetController c(twoGroups(), paramsFor(kFrameMs), RenderOptions(), &kMask);
  const std::vector<TraceFrame> trace = walkTrace(3000, 1 << 30, 1 << 30, 1.0, 1, 0.03, 3);
  const SimRun run = simulate(c, trace);
  // It settles within the first second; afterwards the noise (+-3%) must not move it.
  int changesLater = 0;
  BudgetController again(twoGroups(), paramsFor(kFrameMs), RenderOptions(), &kMask);
  const BudgetController plant = again;
  for (size_t f = 0; f < trace.size(); ++f) {
    const ControlDecision d = again.decide(double(f) * kFrameMs);
    if (f > 180 && std::string(d.change) != "hold") ++changesLater;
    again.observe(frameCosts(plant, d.setting, trace[f]));
  }
  EXPECT_LE(changesLater, 2);
  EXPECT_LE(run.p99(), kFrameMs);
}

// A renderer's first frame pays for its allocations (33 ms against 3 on the H200's Sponza walk):
// the probe's first measurement is not counted, so the controller settles as if it had not been.
TEST(BudgetController, IgnoresTheFirstFramesAllocations) {
  const std::vector<TraceFrame> steady = walkTrace(400, 1 << 30, 1 << 30, 1.0, 1, 0.0, 2);
  std::vector<TraceFrame> cold = steady;
  cold[0].noise = 10.0;
  BudgetController a(twoGroups(), paramsFor(kFrameMs), RenderOptions(), &kMask);
  BudgetController b(twoGroups(), paramsFor(kFrameMs), RenderOptions(), &kMask);
  const SimRun warmRun = simulate(a, steady), coldRun = simulate(b, cold);
  EXPECT_EQ(a.current(), b.current());
  for (size_t f = 2; f < steady.size(); ++f) ASSERT_EQ(warmRun.ms[f], coldRun.ms[f]) << "frame " << f;
  EXPECT_EQ(coldRun.lowers, warmRun.lowers);
}

// A recorded walk: each frame's measured costs divided by its setting's scales are the view's unit
// costs (a term the setting did not run is carried from the nearest frame that ran it).
std::vector<TraceFrame> recordedTrace(const BudgetController& c, const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::vector<TraceFrame> trace;
  std::vector<std::array<bool, 5>> known;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    ControlSetting s;
    int fov = 0, levels[3] = {0, 0, 0};
    ControlCosts ms;
    fields >> s.photons >> s.radius >> s.denoise >> fov >> levels[0] >> levels[1] >> levels[2] >> ms.photonMs >> ms.densityMs >>
        ms.rayMs >> ms.denoiseMs >> ms.restMs;
    EXPECT_TRUE(bool(fields)) << line;
    s.foveated = fov != 0;
    for (int g = 0; g < 3; ++g) s.levels[size_t(g)] = uint8_t(levels[g]);
    const ControlCosts scale = c.scaleOf(s);
    TraceFrame f;
    double* unit[5] = {&f.units.photonMs, &f.units.densityMs, &f.units.rayMs, &f.units.denoiseMs, &f.units.restMs};
    const double measured[5] = {ms.photonMs, ms.densityMs, ms.rayMs, ms.denoiseMs, ms.restMs};
    const double scales[5] = {scale.photonMs, scale.densityMs, scale.rayMs, scale.denoiseMs, scale.restMs};
    std::array<bool, 5> k{};
    for (int t = 0; t < 5; ++t) k[size_t(t)] = scales[t] > 0, *unit[t] = scales[t] > 0 ? measured[t] / scales[t] : 0.0;
    trace.push_back(f);
    known.push_back(k);
  }
  for (int t = 0; t < 5; ++t) {  // carry each term forward, then backward, over the frames that lack it
    auto term = [t](TraceFrame& f) -> double& {
      double* unit[5] = {&f.units.photonMs, &f.units.densityMs, &f.units.rayMs, &f.units.denoiseMs, &f.units.restMs};
      return *unit[t];
    };
    std::vector<bool> have(trace.size());
    for (size_t i = 0; i < trace.size(); ++i) have[i] = known[i][size_t(t)];
    for (size_t i = 1; i < trace.size(); ++i)
      if (!have[i] && have[i - 1]) term(trace[i]) = term(trace[i - 1]), have[i] = true;
    for (size_t i = trace.size() - 1; i-- > 0;)
      if (!have[i] && have[i + 1]) term(trace[i]) = term(trace[i + 1]), have[i] = true;
  }
  return trace;
}

// The H200's Sponza walk (tests/data/sponza_walk_h200.trace, its calibrated profile beside it)
// replayed at 11.1 and 5.5 ms: p99 under the budget, at most 0.5 % of frames over it, an error
// near the best fixed setting's in hindsight; and the walk's best setting costs several budgets.
TEST(BudgetController, HoldsTheBudgetOnTheRecordedSponzaWalk) {
  const std::string data = PVR_TEST_DATA;
  const ControlProfile profile = ControlProfile::load(data + "/sponza_h200.profile.json", {"rest", "floor", "decorations"});
  for (double budget : {kFrameMs, 5.5}) {
    BudgetController c(profile, paramsFor(budget), RenderOptions(), &kMask);
    const std::vector<TraceFrame> trace = recordedTrace(c, data + "/sponza_walk_h200.trace");
    ASSERT_EQ(trace.size(), 2700u);
    double worstBest = 0;
    for (size_t f = 1; f < trace.size(); ++f) worstBest = std::max(worstBest, frameCosts(c, c.best(), trace[f]).total());
    EXPECT_GT(worstBest, 2.0 * budget) << "the best setting must not fit: there is nothing to control otherwise";
    const SimRun run = simulate(c, trace);
    EXPECT_LE(run.p99(), budget) << budget;
    EXPECT_LE(run.over(budget), 0.005) << budget;
    BudgetController model(profile, paramsFor(budget), RenderOptions(), &kMask);
    double bestFixed = 1e30;
    ControlSetting bestFixedSetting;
    for (const ControlSetting& s : everySetting(profile, true)) {
      const SimRun fixed = simulateFixed(model, s, trace);
      if (fixed.p99() <= budget && fixed.over(budget) <= 0.005 && fixed.meanError() < bestFixed)
        bestFixed = fixed.meanError(), bestFixedSetting = s;
    }
    std::printf("controller ends at %s (%.2f ms); best fixed %s\n", BudgetController::toJson(c.current(), profile).dump().c_str(),
                c.predictMs(c.current()), BudgetController::toJson(bestFixedSetting, profile).dump().c_str());
    // On this walk the cost is nearly constant after its first seconds, so the best fixed setting,
    // chosen in hindsight from the whole walk at the budget's edge, is close to the controller's
    // final one plus what its safety margin leaves unused: the controller must stay within 20 %
    // of it (measured: 5 % above at 11.1 ms, 1 % above at 5.5 ms; docs/ray-vr.md).
    EXPECT_LT(run.meanError(), 1.2 * bestFixed) << budget;
    std::printf("budget %.2f ms: best setting up to %.1f ms (%.1fx), controller p99 %.2f ms, %.2f %% over, mean "
                "predicted relMSE %.4f against the best fixed setting's %.4f\n",
                budget, worstBest, worstBest / budget, run.p99(), 100.0 * run.over(budget), run.meanError(), bestFixed);
  }
}

TEST(BudgetController, RaisesNoFasterThanItsRate) {
  BudgetController c(twoGroups(), paramsFor(kFrameMs), RenderOptions(), &kMask);
  // Very heavy at first (10x), then a long light stretch: it climbs a few steps at a time.
  const std::vector<TraceFrame> trace = walkTrace(2000, 0, 200, 10.0, 1, 0.02, 5);
  const SimRun run = simulate(c, trace);
  ASSERT_GE(run.raises, 2);
  EXPECT_LE(run.p99(), kFrameMs);
  const double rate = c.params().maxRaisesPerSecond;
  for (size_t i = 1; i < run.raiseTimes.size(); ++i)
    EXPECT_GE(run.raiseTimes[i] - run.raiseTimes[i - 1], 1000.0 / rate - 1e-9);
}

TEST(BudgetController, PredictsOtherSettingsFromOneMeasuredFrame) {
  BudgetController c(twoGroups(), paramsFor(kFrameMs), RenderOptions(), &kMask);
  TraceFrame f = walkTrace(1, 1 << 30, 1 << 30, 1.0, 1, 0.0, 1)[0];
  // The first frame probes without the denoiser: its cost per iteration is the profile's until measured.
  f.units.denoiseMs = c.profile().denoiseMsPerIteration;
  const ControlDecision d = c.decide(0);
  EXPECT_STREQ(d.change, "start");
  EXPECT_EQ(d.setting.photons, 0);
  c.observe(frameCosts(c, d.setting, f));
  for (const ControlSetting& s : everySetting(c.profile(), true))
    ASSERT_NEAR(c.predictMs(s), frameCosts(c, s, f).total(), 1e-9);
}

// The quality model fitted from measurements (the effects suite at a view, the controller suite
// on a walk): measured errors that follow an additive model (another profile's, its photon terms
// weighted by the groups at gi) give back that model's prediction for every setting, each knob's
// step measured alone from the best setting; a measured step that lowers the error where the
// model cannot (photons, levels: noise) counts as 0.
TEST(BudgetController, FittedErrorsReproduceTheMeasuredModel) {
  ControlProfile truth = twoGroups();
  truth.topError = 0.031;
  truth.photonError = {0.09, 0.06, 0.04, 0.025, 0.012, 0.004, 0.0};
  truth.radiusError = {0.011, 0.0, 0.002};
  truth.denoiseError = {0.0, -0.004, -0.009, -0.010, -0.0105};
  truth.foveatedError = 0.037;
  truth.photonErrorUndenoised = {0.4, 0.3, 0.2, 0.1, 0.06, 0.02, 0.0};
  truth.radiusErrorUndenoised = {0.05, 0.0, 0.02};  // 0 at the top's steps, as fitted
  truth.levelError = {{0.21, 0.05, 0.02, 0.0}, {0.13, 0.03, 0.01, 0.0}};
  const BudgetController measured(truth, paramsFor(kFrameMs), RenderOptions(), &kMask);
  ControlProfile fitted = twoGroups();  // the generic model's errors, to be replaced
  int calls = 0;
  fitted.fitErrors(measured.best(), [&](const ControlSetting& s) { return ++calls, measured.predictError(s); });
  // The top, each other step alone, and the photon and radius steps again without the denoiser.
  EXPECT_EQ(calls, 1 + 6 + 2 + 4 + 1 + 2 * 3 + 6 + 2);
  fitted.validate();
  const BudgetController model(fitted, paramsFor(kFrameMs), RenderOptions(), &kMask);
  EXPECT_EQ(model.best(), measured.best());
  for (const ControlSetting& s : everySetting(fitted, true))
    ASSERT_NEAR(model.predictError(s), measured.predictError(s), 1e-12);

  // Ladders measured at a denoise step other than the least-error one (the previous profile's
  // best, where the walk then finds another step better): the mix is anchored where they were
  // measured, and the fit still gives back the model it measured.
  ControlProfile truthAt3 = truth;
  truthAt3.laddersDenoiseStep = 3;
  const BudgetController measuredAt3(truthAt3, paramsFor(kFrameMs), RenderOptions(), &kMask);
  ControlSetting top3 = measuredAt3.best();
  top3.denoise = 3;
  ControlProfile fittedAt3 = twoGroups();
  fittedAt3.fitErrors(top3, [&](const ControlSetting& s) { return measuredAt3.predictError(s); });
  EXPECT_EQ(fittedAt3.laddersDenoiseStep, 3);
  const BudgetController modelAt3(fittedAt3, paramsFor(kFrameMs), RenderOptions(), &kMask);
  for (const ControlSetting& s : everySetting(fittedAt3, true))
    ASSERT_NEAR(modelAt3.predictError(s), measuredAt3.predictError(s), 1e-12);

  // A measured photon or level step below the top's error (noise) is no gain in the model.
  ControlProfile noisy = twoGroups();
  noisy.fitErrors(measured.best(), [&](const ControlSetting& s) {
    const bool fewerPhotons = s.photons == 5, floorShadows = s.levels[1] == uint8_t(EffectLevel::Shadows);
    return measured.predictError(s) - (fewerPhotons ? 0.02 : 0.0) - (floorShadows ? 0.05 : 0.0);
  });
  EXPECT_EQ(noisy.photonError[5], 0.0);
  EXPECT_EQ(noisy.levelError[1][size_t(EffectLevel::Shadows)], 0.0);
  EXPECT_NEAR(noisy.photonError[4], truth.photonError[4], 1e-12);
}

// The photon knobs with and without the denoiser: the same step costs more undenoised (the
// Sponza walk's fit: 512^2 photons without denoising 0.048, the denoised steps' sum 0.025), so a
// model that adds the denoised steps to the denoiser's own term picks too few photons without it.
TEST(BudgetController, FewerPhotonsCostMoreWithoutTheDenoiser) {
  ControlProfile p = twoGroups();
  p.topError = 0.008;
  p.photonError = {0.021, 0.010, 0.005, 0.0025, 0.001, 0.0004, 0.0};
  p.radiusError = {0.0006, 0.0001, 0.0};
  p.denoiseError = {0.0, -0.0055, -0.0058, -0.0059, -0.0060};  // the cheapest step gives most of the gain
  const ControlProfile additive = p;
  p.photonErrorUndenoised = {0.16, 0.08, 0.04, 0.026, 0.013, 0.006, 0.0};
  p.radiusErrorUndenoised = {0.09, 0.03, 0.0};
  p.validate();
  EXPECT_DOUBLE_EQ(p.undenoisedWeight(0), 1.0);
  EXPECT_DOUBLE_EQ(p.undenoisedWeight(4), 0.0);
  EXPECT_DOUBLE_EQ(p.undenoisedWeight(2), (-0.0058 + 0.0060) / 0.0060);
  EXPECT_DOUBLE_EQ(additive.undenoisedWeight(0), 0.0);  // no undenoised ladder: the additive model
  const BudgetController with(p, paramsFor(kFrameMs), RenderOptions(), &kMask);
  const BudgetController without(additive, paramsFor(kFrameMs), RenderOptions(), &kMask);
  ControlSetting off = with.best(), on = with.best();
  off.denoise = 0, off.photons = 3;  // 362^2 photons, no denoiser
  on.denoise = 1, on.photons = 1;    // 181^2 photons, the cheapest denoise step
  // Every step at the best denoiser is the same in both models; without it, the measured ladders.
  for (const ControlSetting& s : everySetting(p, true)) {
    if (s.denoise != with.best().denoise) continue;
    ASSERT_DOUBLE_EQ(with.predictError(s), without.predictError(s));
  }
  ControlSetting undenoisedTop = with.best();
  undenoisedTop.denoise = 0;
  ControlSetting fewer = undenoisedTop;
  fewer.photons = 3, fewer.radius = 1;
  EXPECT_NEAR(with.predictError(fewer) - with.predictError(undenoisedTop), 0.026 + 0.03, 1e-12);  // both groups at gi
  // The additive model prefers dropping the denoiser to dropping photons; the measured one, not.
  EXPECT_LT(without.predictError(off), without.predictError(on));
  EXPECT_GT(with.predictError(off), with.predictError(on));
  // The ladders round-trip through a profile file, and one of the wrong length is refused.
  const ControlProfile again = [&] {
    const std::string path = testing::TempDir() + "undenoised_profile.json";
    std::ofstream(path) << p.toJson().dump();
    return ControlProfile::load(path, {"rest", "floor"});
  }();
  EXPECT_EQ(again.photonErrorUndenoised, p.photonErrorUndenoised);
  EXPECT_EQ(again.radiusErrorUndenoised, p.radiusErrorUndenoised);
  ControlProfile bad = p;
  bad.radiusErrorUndenoised.pop_back();
  EXPECT_THROW(bad.validate(), Error);
  bad = p;
  bad.radiusErrorUndenoised.clear();
  EXPECT_THROW(bad.validate(), Error);
  bad = p;
  bad.denoiseIterations = {2, 4, 5, 5, 5}, bad.denoiseDirectIterations = {2, 2, 2, 3, 5};  // no step without the denoiser
  EXPECT_THROW(bad.validate(), Error);
  bad = p;
  bad.laddersDenoiseStep = 5;
  EXPECT_THROW(bad.validate(), Error);
}

TEST(BudgetController, OptionsCarryTheSetting) {
  RenderOptions base;
  base.gather.density.radius = 0.1f;
  BudgetController c(twoGroups(), paramsFor(kFrameMs), base, &kMask);
  ControlSetting s = c.best();
  s.photons = 2, s.radius = 0, s.denoise = 0, s.foveated = true;
  s.levels[1] = uint8_t(EffectLevel::Reflections);
  RenderOptions o = c.optionsFor(s);
  EXPECT_EQ(o.photonsX, c.profile().photonSides[2]);
  EXPECT_EQ(o.photonsY, c.profile().photonSides[2]);
  EXPECT_FLOAT_EQ(o.gather.density.radius, 0.1f * c.profile().radiusScales[0]);
  EXPECT_FALSE(o.denoise.enabled);
  EXPECT_EQ(o.foveation.mask, &kMask);
  EXPECT_EQ(o.gather.groupEffects[0], uint8_t(EffectLevel::Gi));
  EXPECT_EQ(o.gather.groupEffects[1], uint8_t(EffectLevel::Reflections));
  EXPECT_EQ(o.gather.groupEffects[2], kOwnEffectLevel);
  // Nothing at gi: nothing gathers photons, the fewest are traced.
  s.levels[0] = s.levels[1] = uint8_t(EffectLevel::Shadows);
  s.denoise = 2;
  o = c.optionsFor(s);
  EXPECT_EQ(o.photonsX, c.profile().photonSides.front());
  EXPECT_TRUE(o.denoise.enabled);
  EXPECT_EQ(o.denoise.params.iterations, c.profile().denoiseIterations[2]);
  EXPECT_EQ(o.denoise.params.directIterations, c.profile().denoiseDirectIterations[2]);
  // The direct signal through fewer passes than the photon map's: its step costs less than all
  // passes over both signals, more than the photon map's passes alone.
  ASSERT_LT(c.profile().denoiseDirectIterations[2], c.profile().denoiseIterations[2]);
  EXPECT_LT(c.scaleOf(s).denoiseMs, double(c.profile().denoiseIterations[2]));
  EXPECT_GT(c.scaleOf(s).denoiseMs, c.profile().photonMapPassShare * c.profile().denoiseIterations[2]);
  EXPECT_DOUBLE_EQ(c.scaleOf(s).densityMs, c.profile().densityFixedShare) << "only the density stage's fixed part runs";
  // Options asking for less than gi cap the group.
  base.gather.groupEffects[1] = uint8_t(EffectLevel::Shadows);
  BudgetController capped(twoGroups(), paramsFor(kFrameMs), base, &kMask);
  EXPECT_EQ(capped.best().levels[1], uint8_t(EffectLevel::Shadows));
  EXPECT_EQ(capped.best().levels[0], uint8_t(EffectLevel::Gi));
}

TEST(BudgetController, ProfilesRoundTripAndBadOnesAreRefused) {
  ControlProfile p = twoGroups();
  p.scene = "test";
  p.levelError[1][0] = 0.125;
  p.levelRayCost[1][1] = -0.25;
  const std::string path = ::testing::TempDir() + "/profile.json";
  {
    std::ofstream out(path);
    out << p.toJson().dump(2);
  }
  const ControlProfile q = ControlProfile::load(path, {"rest", "floor"});
  EXPECT_EQ(q.toJson(), p.toJson());
  EXPECT_THROW(ControlProfile::load(path, {"rest", "floor", "windows"}), Error);  // a group it was not calibrated for
  EXPECT_THROW(ControlProfile::load(path + ".missing", {"rest"}), Error);
  auto refused = [&](const std::string& text) {
    std::ofstream(path) << text;
    try {
      ControlProfile::load(path, {"rest", "floor"});
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      return true;
    }
    return false;
  };
  EXPECT_TRUE(refused("{not json"));
  EXPECT_TRUE(refused("[1, 2]"));
  nlohmann::json j = p.toJson();
  j["photon_sides"] = {512, 256, 1024, 128, 181, 362, 724};
  EXPECT_TRUE(refused(j.dump()));
  j = p.toJson();
  j["error"]["photons"] = {0.1};
  EXPECT_TRUE(refused(j.dump()));
  // Numbers the ladders' types do not hold: refused by name, never cast (a cast is undefined there).
  for (const char* ladder : {"photon_sides", "denoise_iterations", "radius_scales"})
    for (const double bad : {1e20, -1e300, 2.5}) {
      const bool integers = std::string(ladder) != "radius_scales";
      if (!integers && bad != -1e300) continue;  // floats that fit: the ladder's own range check's
      j = p.toJson();
      j[ladder][0] = bad;
      std::ofstream(path) << j.dump();
      try {
        ControlProfile::load(path, {"rest", "floor"});
        ADD_FAILURE() << ladder << " " << bad << " loaded";
      } catch (const Error& e) {
        const std::string expected = std::string("each of '") + ladder + (integers ? "' must be an integer" : "' must be a finite number");
        EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
      }
    }
  j = p.toJson();
  j["error"]["groups"]["floor"]["sparkle"] = 1.0;
  EXPECT_TRUE(refused(j.dump()));
  j = p.toJson();
  j["cost"]["foveated_samples"] = 0.0;
  EXPECT_TRUE(refused(j.dump()));
  // The denoise ladder: direct passes within 1..the step's passes, steps rising in cost.
  j = p.toJson();
  j["denoise_direct_iterations"][1] = j["denoise_iterations"][1].get<int>() + 1;
  EXPECT_TRUE(refused(j.dump()));
  j = p.toJson();
  j["denoise_direct_iterations"][1] = 0;
  EXPECT_TRUE(refused(j.dump()));
  j = p.toJson();
  j["denoise_direct_iterations"].erase(1);
  EXPECT_TRUE(refused(j.dump()));
  j = p.toJson();
  j["denoise_iterations"] = {0, 2, 2, 4, 5};
  j["denoise_direct_iterations"] = {0, 2, 1, 2, 5};  // the third step costs less than the second
  EXPECT_TRUE(refused(j.dump()));
  j = p.toJson();
  j["cost"]["photon_map_pass_share"] = 1.5;
  EXPECT_TRUE(refused(j.dump()));
  // A profile from before the direct passes: every pass filters both signals.
  j = p.toJson();
  j["denoise_iterations"] = {0, 2, 4};
  j["error"]["denoise"] = {0.0, -0.005, -0.007};
  j.erase("denoise_direct_iterations");
  std::ofstream(path) << j.dump();
  const ControlProfile old = ControlProfile::load(path, {"rest", "floor"});
  EXPECT_EQ(old.denoiseDirectIterations, old.denoiseIterations);
  EXPECT_DOUBLE_EQ(old.denoisePasses(2), 4.0);
  EXPECT_THROW(BudgetController(twoGroups(), paramsFor(-1.0), RenderOptions(), &kMask), Error);
  EXPECT_THROW(BudgetController(twoGroups(), paramsFor(std::nan("")), RenderOptions(), &kMask), Error);
}

// `--budget-ms display`: the display's period drops from 11.1 ms (90 Hz) to 8.3 ms (120 Hz) and
// rises to 22.2 ms (45 Hz, a runtime's reprojection mode). Within a second of each change the
// frames keep to the new budget, and each frame is counted against the budget of its decision.
TEST(BudgetController, FollowsTheDisplaysPeriod) {
  BudgetController c(twoGroups(), paramsFor(kFrameMs), RenderOptions(), &kMask);
  const BudgetController plant = c;
  const std::vector<TraceFrame> trace = walkTrace(900, 900, 900, 1.0, 1, 0.02, 5);
  ControlLog log;
  std::vector<double> ms;
  for (size_t f = 0; f < trace.size(); ++f) {
    if (f == 300) c.setBudget(1000.0 / 120.0);
    if (f == 600) c.setBudget(1000.0 / 45.0);
    c.setBudget(0.0);  // unknown (a runtime before its first frame): ignored
    const ControlDecision d = c.decide(double(f) * kFrameMs);
    EXPECT_EQ(d.budgetMs, f < 300 ? kFrameMs : (f < 600 ? 1000.0 / 120.0 : 1000.0 / 45.0)) << f;
    const ControlCosts costs = frameCosts(plant, d.setting, trace[f]);
    log.add(d, costs.total(), costs);
    ms.push_back(costs.total());
    c.observe(costs);
  }
  auto window = [&](size_t from, size_t to) { return latencyStats(std::vector<double>(ms.begin() + long(from), ms.begin() + long(to))); };
  EXPECT_LE(window(90, 300).p99, kFrameMs);
  EXPECT_LE(window(390, 600).p99, 1000.0 / 120.0);
  EXPECT_LE(window(690, 900).p99, 1000.0 / 45.0);
  // The slower display leaves room, which the controller takes back: more work per frame.
  EXPECT_GT(window(800, 900).mean, 1.3 * window(200, 300).mean);
  size_t over = 0;
  for (size_t f = 0; f < ms.size(); ++f) over += ms[f] > (f < 300 ? kFrameMs : (f < 600 ? 1000.0 / 120.0 : 1000.0 / 45.0));
  EXPECT_EQ(log.framesOverTheirBudget(), over);
  const nlohmann::json j = log.toJson(c);
  EXPECT_EQ(j["frames_over_budget"].get<size_t>(), over);
  EXPECT_EQ(j["frames"][450]["budget_ms"].get<double>(), 1000.0 / 120.0);
}

TEST(BudgetController, LogsEveryFrame) {
  BudgetController c(twoGroups(), paramsFor(5.5), RenderOptions(), &kMask);
  const BudgetController plant = c;
  const std::vector<TraceFrame> trace = walkTrace(300, 100, 200, 3.0, 20, 0.02, 9);
  ControlLog log;
  for (size_t f = 0; f < trace.size(); ++f) {
    const ControlDecision d = c.decide(double(f) * kFrameMs);
    const ControlCosts costs = frameCosts(plant, d.setting, trace[f]);
    log.add(d, costs.total(), costs);
    c.observe(costs);
  }
  const nlohmann::json j = log.toJson(c);
  ASSERT_EQ(j["frames"].size(), trace.size());
  EXPECT_EQ(j["budget_ms"], 5.5);
  EXPECT_EQ(j["frames_over_budget"].get<size_t>(), log.framesOver(5.5));
  EXPECT_GT(j["changes"].get<size_t>(), 0u);
  EXPECT_EQ(j["frames"][0]["change"], "start");
  EXPECT_TRUE(j["frames"][150]["setting"]["levels"].contains("floor"));
  // The generic profile's ratio is the plant's (0.25): measured at the start within the noise.
  EXPECT_NEAR(j["foveated_ratio_at_end"].get<double>(), 0.25, 0.25 * 0.05);
}

// A profile whose foveated ratio is 4x too low (the H100's Sponza walk, 2026-12-07: a ratio of
// samples, 2.6 %, where the pass took 10 % of the full-resolution time): the controller that
// believed it stayed foveated for the whole walk, predicting full resolution at 4x its cost.
// Here foveation costs much quality (as on Sponza against full-resolution references), so a
// full-resolution setting with fewer photons is better and fits.
ControlProfile foveationCostsQuality(double foveatedSamples) {
  ControlProfile p = twoGroups();
  p.foveatedError = 0.09;
  p.foveatedSamples = foveatedSamples;
  return p;
}

TEST(BudgetController, MeasuresTheFoveatedPassAtTheStart) {
  const BudgetController plant(foveationCostsQuality(0.1), paramsFor(kFrameMs), RenderOptions(), &kMask);
  BudgetController c(foveationCostsQuality(0.025), paramsFor(kFrameMs), RenderOptions(), &kMask);
  const std::vector<TraceFrame> trace = walkTrace(900, 1 << 30, 1 << 30, 1.0, 1, 0.02, 4);
  std::vector<bool> foveated;
  SimRun run;
  for (size_t f = 0; f < trace.size(); ++f) {
    const ControlDecision d = c.decide(double(f) * kFrameMs);
    foveated.push_back(d.setting.foveated);
    const ControlCosts costs = frameCosts(plant, d.setting, trace[f]);
    run.ms.push_back(costs.total()), run.error.push_back(plant.predictError(d.setting));
    c.observe(costs);
  }
  // The probes: foveated twice (the first frame's allocations), then at full resolution.
  EXPECT_TRUE(foveated[0] && foveated[1] && !foveated[2]);
  EXPECT_NEAR(c.foveatedRatio(), 0.1, 0.1 * 0.05);  // the trace's noise is +-2 % a frame
  EXPECT_FALSE(c.current().foveated);
  EXPECT_LE(run.p99(), kFrameMs);
  double bestFixed = 1e30;
  for (const ControlSetting& s : everySetting(plant.profile(), true)) {
    const SimRun fixed = simulateFixed(plant, s, trace);
    if (fixed.p99() <= kFrameMs) bestFixed = std::min(bestFixed, fixed.meanError());
  }
  EXPECT_LT(run.meanError(), 1.2 * bestFixed);  // its margin against a fixed setting at the edge, as on the recorded walk
}

// The ratio changes after the start (another part of the scene): the switch into the foveated
// pass, when a heavy view forces it, measures it again from the frames either side, within the
// noise and the view's change from one frame to the next (a 1 s turn). The profile's ratio is 4x
// off, and the start-up probe corrects it first.
TEST(BudgetController, MeasuresTheFoveatedPassAgainAtASwitch) {
  const BudgetController before(foveationCostsQuality(0.1), paramsFor(kFrameMs), RenderOptions(), &kMask);
  const BudgetController after(foveationCostsQuality(0.18), paramsFor(kFrameMs), RenderOptions(), &kMask);
  BudgetController c(foveationCostsQuality(0.025), paramsFor(kFrameMs), RenderOptions(), &kMask);
  const std::vector<TraceFrame> trace = walkTrace(1200, 600, 1200, 4.0, 90, 0.02, 6);
  int switches = 0;
  bool wasFoveated = false;
  for (size_t f = 0; f < trace.size(); ++f) {
    const ControlDecision d = c.decide(double(f) * kFrameMs);
    if (f > 3 && d.setting.foveated != wasFoveated) ++switches;
    wasFoveated = d.setting.foveated;
    c.observe(frameCosts(f < 300 ? before : after, d.setting, trace[f]));
    if (f == 299) {
      EXPECT_EQ(switches, 0);
      EXPECT_NEAR(c.foveatedRatio(), 0.1, 0.1 * 0.05);  // the probe's, within the noise
    }
  }
  ASSERT_GT(switches, 0);
  EXPECT_TRUE(c.current().foveated);
  EXPECT_NEAR(c.foveatedRatio(), 0.18, 0.18 * 0.1);
}

}  // namespace
}  // namespace pvr
