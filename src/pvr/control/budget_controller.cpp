#include "pvr/control/budget_controller.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>

#include "pvr/util/error.h"
#include "pvr/util/json_number.h"
#include "pvr/util/latency_stats.h"

namespace pvr {
namespace {

constexpr double kMinShare = 0.02;                   // a term never predicted to vanish
constexpr size_t kMaxExhaustive = 50000;             // settings searched one by one when lowering

bool finite(double v) { return std::isfinite(v); }

// Knob steps from a to b that a viewer sees: a ladder index or a level moved by one counts one;
// the photon count and radius only where a group gathers photons on both sides (entering gi
// brings the photons it is entered with).
int stepsBetween(const ControlSetting& a, const ControlSetting& b, int groups) {
  bool giA = false, giB = false;
  int steps = std::abs(a.denoise - b.denoise) + (a.foveated != b.foveated ? 1 : 0);
  for (int g = 0; g < groups; ++g) {
    steps += std::abs(int(a.levels[size_t(g)]) - int(b.levels[size_t(g)]));
    giA |= a.levels[size_t(g)] == uint8_t(EffectLevel::Gi);
    giB |= b.levels[size_t(g)] == uint8_t(EffectLevel::Gi);
  }
  if (giA && giB) steps += std::abs(a.photons - b.photons) + std::abs(a.radius - b.radius);
  return steps;
}

template <class T>
std::vector<T> readList(const nlohmann::json& j, const char* key, const std::vector<T>& fallback) {
  if (!j.contains(key)) return fallback;
  if (!j[key].is_array()) throw Error(std::string("'") + key + "' must be a list");
  std::vector<T> out;
  for (const nlohmann::json& n : j[key]) out.push_back(jsonNumber<T>(n, std::string("each of '") + key + "'"));
  return out;
}

std::array<double, kControlledLevels> readLevels(const nlohmann::json& j, const std::string& what) {
  std::array<double, kControlledLevels> out{};
  if (!j.is_object()) throw Error(what + " must map effect levels to numbers");
  for (const auto& [name, value] : j.items()) {
    int level = -1;
    for (int l = 0; l < kControlledLevels; ++l)
      if (name == effectLevelName(EffectLevel(l))) level = l;
    if (level < 0) throw Error(what + " has '" + name + "', not one of raster, shadows, reflections, gi");
    if (!value.is_number()) throw Error(what + "'s '" + name + "' must be a number");
    out[size_t(level)] = value.get<double>();
  }
  return out;
}

nlohmann::json levelsJson(const std::array<double, kControlledLevels>& v) {
  nlohmann::json j = nlohmann::json::object();
  for (int l = 0; l < kControlledLevels; ++l) j[effectLevelName(EffectLevel(l))] = v[size_t(l)];
  return j;
}

}  // namespace

ControlCosts ControlCosts::of(const StageTimings& t, double frameMs) {
  ControlCosts c;
  c.photonMs = t.photonTraceMs + t.mapBuildMs;
  c.densityMs = t.densityMs[0] + t.densityMs[1];
  c.rayMs = t.eyeRayMs[0] + t.eyeRayMs[1];
  c.denoiseMs = t.denoiseMs[0] + t.denoiseMs[1];
  // A backend that times the eye pass as one (the CPU's fused rays and estimates): all of it
  // scales as the eye rays do.
  if (c.rayMs == 0 && c.densityMs == 0) c.rayMs = std::max(0.0, t.eyeMs[0] + t.eyeMs[1] - c.denoiseMs);
  c.restMs = std::max(0.0, frameMs - c.photonMs - c.densityMs - c.rayMs - c.denoiseMs);
  return c;
}

ControlProfile ControlProfile::generic(const std::vector<std::string>& groups) {
  ControlProfile p;
  p.scene = "generic";
  p.groups = groups.empty() ? std::vector<std::string>{"rest"} : groups;
  const double top = double(p.photonSides.back()) * p.photonSides.back();
  for (uint32_t side : p.photonSides) p.photonError.push_back(0.01 * (top / (double(side) * side) - 1.0));
  for (float s : p.radiusScales) p.radiusError.push_back(0.01 * (1.0 / (s * s) - 1.0) + 0.01 * (s * s - 1.0));
  p.denoiseError = {0.0, -0.005, -0.0065, -0.007, -0.0072};
  const double share = 1.0 / double(p.groups.size());
  for (size_t g = 0; g < p.groups.size(); ++g) {
    p.levelError.push_back({0.3 * share, 0.1 * share, 0.08 * share, 0.0});
    p.levelRayCost.push_back({-0.7 * share, -0.4 * share, -0.2 * share, 0.0});
    p.densityShare.push_back(share);
  }
  return p;
}

void ControlProfile::validate() const {
  const size_t g = groups.size();
  if (g == 0 || g > size_t(kMaxEffectGroups)) throw Error("a profile needs 1 to " + std::to_string(kMaxEffectGroups) + " groups");
  if (photonSides.empty() || radiusScales.empty() || denoiseIterations.empty())
    throw Error("the photon, radius and denoise ladders must not be empty");
  for (size_t i = 0; i < photonSides.size(); ++i)
    if (photonSides[i] < 16 || photonSides[i] > 8192 || (i && photonSides[i] <= photonSides[i - 1]))
      throw Error("photon sides must rise, each within 16..8192");
  for (float s : radiusScales)
    if (!(s > 0.05f && s < 20.0f)) throw Error("radius scales must be within 0.05..20");
  if (!(photonMapPassShare > 0.0 && photonMapPassShare <= 1.0))
    throw Error("the photon-map pass share must be within (0, 1]");
  if (denoiseDirectIterations.size() != denoiseIterations.size())
    throw Error("the denoise ladder needs one direct iteration count per step");
  for (size_t i = 0; i < denoiseIterations.size(); ++i) {
    const int n = denoiseIterations[i], direct = denoiseDirectIterations[i];
    if (n < 0 || n > kMaxDenoiseIterations)
      throw Error("denoise iterations must be within 0.." + std::to_string(kMaxDenoiseIterations));
    if (n == 0 ? direct != 0 : direct < 1 || direct > n)
      throw Error("denoise direct iterations must be within 1..the step's iterations (0 where the denoiser is off)");
    if (i && !(denoisePasses(int(i)) > denoisePasses(int(i) - 1))) throw Error("the denoise ladder's steps must rise in cost");
  }
  if (photonError.size() != photonSides.size() || radiusError.size() != radiusScales.size() ||
      denoiseError.size() != denoiseIterations.size())
    throw Error("each ladder needs one error per step");
  if (photonErrorUndenoised.empty() != radiusErrorUndenoised.empty() ||
      (!photonErrorUndenoised.empty() &&
       (photonErrorUndenoised.size() != photonSides.size() || radiusErrorUndenoised.size() != radiusScales.size())))
    throw Error("the undenoised photon and radius errors need one error per step, both or neither");
  if (!photonErrorUndenoised.empty() && denoiseIterations.front() != 0)
    throw Error("undenoised photon and radius errors need a denoise ladder that starts with the denoiser off");
  if (laddersDenoiseStep < -1 || laddersDenoiseStep >= int(denoiseIterations.size()))
    throw Error("the ladders' denoise step must be one of the denoise ladder's steps");
  if (levelError.size() != g || levelRayCost.size() != g || densityShare.size() != g)
    throw Error("level errors, level costs and density shares need one entry per group");
  auto check = [](double v, const char* what) {
    if (!finite(v)) throw Error(std::string(what) + " must be finite");
  };
  check(topError, "the top error");
  check(foveatedError, "the foveated error");
  if (!(foveatedSamples > 0.0 && foveatedSamples <= 1.0)) throw Error("foveated samples must be within (0, 1]");
  if (!(photonFixedShare >= 0.0 && photonFixedShare < 1.0) || !(densityFixedShare >= 0.0 && densityFixedShare < 1.0))
    throw Error("the fixed shares of the photon and density costs must be within [0, 1)");
  if (!(denoiseMsPerIteration >= 0.0) || !finite(denoiseMsPerIteration)) throw Error("denoise ms per iteration must be >= 0");
  for (double v : photonError) check(v, "photon errors");
  for (double v : radiusError) check(v, "radius errors");
  for (double v : denoiseError) check(v, "denoise errors");
  for (double v : photonErrorUndenoised) check(v, "undenoised photon errors");
  for (double v : radiusErrorUndenoised) check(v, "undenoised radius errors");
  for (size_t i = 0; i < g; ++i) {
    for (double v : levelError[i]) check(v, "level errors");
    for (double v : levelRayCost[i]) check(v, "level costs");
    if (!(densityShare[i] >= 0.0 && densityShare[i] <= 1.0)) throw Error("density shares must be within 0..1");
  }
}

double ControlProfile::denoisePasses(int step) const {
  const int n = denoiseIterations[size_t(step)], direct = denoiseDirectIterations[size_t(step)];
  return double(direct) + photonMapPassShare * double(n - direct);
}

int ControlProfile::leastErrorDenoiseStep() const {
  return int(std::min_element(denoiseError.begin(), denoiseError.end()) - denoiseError.begin());
}

double ControlProfile::undenoisedWeight(int step) const {
  if (photonErrorUndenoised.empty()) return 0.0;
  if (step == 0) return 1.0;  // the denoiser off (validate: the ladder's first step)
  const size_t measured = size_t(laddersDenoiseStep >= 0 ? laddersDenoiseStep : leastErrorDenoiseStep());
  const double gain = denoiseError.front() - denoiseError[measured];
  if (!(gain > 0.0)) return 0.0;
  return std::clamp((denoiseError[size_t(step)] - denoiseError[measured]) / gain, 0.0, 1.0);
}

void ControlProfile::fitErrors(const ControlSetting& top, const std::function<double(const ControlSetting&)>& errorOf) {
  const double topMeasured = errorOf(top);
  // A knob's step from a measured setting: its error's increase (0 where the step stays there).
  auto stepFrom = [&](const ControlSetting& from, double fromError, auto change) {
    ControlSetting s = from;
    change(s);
    return s == from ? 0.0 : errorOf(s) - fromError;
  };
  auto step = [&](auto change) { return stepFrom(top, topMeasured, change); };
  for (size_t i = 0; i < photonSides.size(); ++i)
    photonError[i] = std::max(0.0, step([&](ControlSetting& s) { s.photons = int(i); }));
  for (size_t i = 0; i < radiusScales.size(); ++i) radiusError[i] = step([&](ControlSetting& s) { s.radius = int(i); });
  for (size_t i = 0; i < denoiseIterations.size(); ++i) denoiseError[i] = step([&](ControlSetting& s) { s.denoise = int(i); });
  // Measured from the top's denoiser: made relative to none, which the top error then includes.
  const double none = denoiseError[0];
  for (double& e : denoiseError) e -= none;
  topError = topMeasured + none;
  foveatedError = step([](ControlSetting& s) { s.foveated = true; });
  photonErrorUndenoised.clear(), radiusErrorUndenoised.clear();
  laddersDenoiseStep = top.denoise;
  if (denoiseIterations.front() == 0 && top.denoise != 0) {
    // The same ladders from the top with the denoiser off (measured above: topMeasured + none).
    ControlSetting off = top;
    off.denoise = 0;
    for (size_t i = 0; i < photonSides.size(); ++i)
      photonErrorUndenoised.push_back(
          std::max(0.0, stepFrom(off, topMeasured + none, [&](ControlSetting& s) { s.photons = int(i); })));
    for (size_t i = 0; i < radiusScales.size(); ++i)
      radiusErrorUndenoised.push_back(stepFrom(off, topMeasured + none, [&](ControlSetting& s) { s.radius = int(i); }));
  }
  for (size_t g = 0; g < groups.size(); ++g)
    for (int level = 0; level < kControlledLevels; ++level)
      levelError[g][size_t(level)] =
          level == top.levels[g] ? 0.0 : std::max(0.0, step([&](ControlSetting& s) { s.levels[g] = uint8_t(level); }));
}

ControlProfile ControlProfile::load(const std::string& path, const std::vector<std::string>& sceneGroups) {
  std::ifstream in(path);
  if (!in) throw Error("cannot open controller profile '" + path + "': no such file or not readable");
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    if (!j.is_object()) throw Error("not a JSON object");
    ControlProfile p;
    p.scene = j.value("scene", "");
    p.device = j.value("device", "");
    p.photonSides = readList(j, "photon_sides", p.photonSides);
    p.radiusScales = readList(j, "radius_scales", p.radiusScales);
    p.denoiseIterations = readList(j, "denoise_iterations", p.denoiseIterations);
    // Profiles from before the direct passes: every pass filters both signals.
    p.denoiseDirectIterations = readList(j, "denoise_direct_iterations", p.denoiseIterations);
    const nlohmann::json& err = j.at("error");
    const nlohmann::json& cost = j.at("cost");
    p.topError = err.at("top").get<double>();
    p.photonError = readList<double>(err, "photons", {});
    p.radiusError = readList<double>(err, "radius", {});
    p.denoiseError = readList<double>(err, "denoise", {});
    p.photonErrorUndenoised = readList<double>(err, "photons_undenoised", {});
    p.radiusErrorUndenoised = readList<double>(err, "radius_undenoised", {});
    if (err.contains("ladders_denoise_step"))
      p.laddersDenoiseStep = jsonNumber<int>(err["ladders_denoise_step"], "'ladders_denoise_step'");
    p.foveatedError = err.at("foveated").get<double>();
    p.foveatedSamples = cost.at("foveated_samples").get<double>();
    p.denoiseMsPerIteration = cost.value("denoise_ms_per_iteration", p.denoiseMsPerIteration);
    p.photonMapPassShare = cost.value("photon_map_pass_share", p.photonMapPassShare);
    p.photonFixedShare = cost.value("photon_fixed_share", p.photonFixedShare);
    p.densityFixedShare = cost.value("density_fixed_share", p.densityFixedShare);
    p.groups = sceneGroups;
    p.levelError.clear(), p.levelRayCost.clear(), p.densityShare.clear();
    for (const std::string& g : sceneGroups) {
      if (!err.at("groups").contains(g)) throw Error("no errors for the scene's effect group '" + g + "'");
      p.levelError.push_back(readLevels(err["groups"][g], "group '" + g + "'s errors"));
      p.levelRayCost.push_back(readLevels(cost.at("groups").at(g), "group '" + g + "'s costs"));
      p.densityShare.push_back(cost.at("density_share").at(g).get<double>());
    }
    p.validate();
    return p;
  } catch (const nlohmann::json::exception& e) {
    throw Error("controller profile '" + path + "': " + e.what());
  } catch (const Error& e) {
    throw Error("controller profile '" + path + "': " + e.what());
  }
}

nlohmann::json ControlProfile::toJson() const {
  nlohmann::json errGroups = nlohmann::json::object(), costGroups = nlohmann::json::object(), shares = nlohmann::json::object();
  for (size_t g = 0; g < groups.size(); ++g) {
    errGroups[groups[g]] = levelsJson(levelError[g]);
    costGroups[groups[g]] = levelsJson(levelRayCost[g]);
    shares[groups[g]] = densityShare[g];
  }
  return {{"scene", scene},
          {"device", device},
          {"photon_sides", photonSides},
          {"radius_scales", radiusScales},
          {"denoise_iterations", denoiseIterations},
          {"denoise_direct_iterations", denoiseDirectIterations},
          {"error", {{"top", topError}, {"photons", photonError}, {"radius", radiusError}, {"denoise", denoiseError},
                     {"photons_undenoised", photonErrorUndenoised}, {"radius_undenoised", radiusErrorUndenoised},
                     {"ladders_denoise_step", laddersDenoiseStep},
                     {"foveated", foveatedError}, {"groups", errGroups}}},
          {"cost", {{"groups", costGroups}, {"density_share", shares}, {"foveated_samples", foveatedSamples},
                    {"denoise_ms_per_iteration", denoiseMsPerIteration}, {"photon_map_pass_share", photonMapPassShare},
                    {"photon_fixed_share", photonFixedShare},
                    {"density_fixed_share", densityFixedShare}}}};
}

BudgetController::BudgetController(const ControlProfile& profile, const BudgetControllerParams& params,
                                   const RenderOptions& base, const FoveationMask* mask)
    : profile_(profile), params_(params), base_(base), mask_(mask), groups_(int(profile.groups.size())) {
  profile_.validate();
  if (!(params.budgetMs > 0.0) || !finite(params.budgetMs) || params.budgetMs > 10000.0)
    throw Error("the frame budget must be a positive number of milliseconds (at most 10000)");
  if (!(params.margin >= 0.0 && params.margin <= params.maxMargin && params.maxMargin < 0.9) ||
      !(params.startMargin >= 0.0 && params.startMargin < 0.9) ||
      !(params.raiseHeadroom >= 0.0 && params.maxMargin + params.raiseHeadroom < 0.95))
    throw Error("the controller's margins must leave part of the budget");
  if (params.window < 1 || params.holdFrames < 0 || !(params.maxRaisesPerSecond > 0.0))
    throw Error("the controller's window, hold and raise rate must be positive");
  if (!mask_ || base.density == DensityScheme::SurfaceCache) params_.foveationAvailable = false;
  // The best setting: the most photons, the radius and denoiser of least error, every group at
  // its ceiling (gi, or lower where the options ask for less).
  best_.photons = int(profile_.photonSides.size()) - 1;
  best_.radius = int(std::min_element(profile_.radiusError.begin(), profile_.radiusError.end()) - profile_.radiusError.begin());
  best_.denoise = profile_.leastErrorDenoiseStep();
  for (int g = 0; g < groups_; ++g) {
    int ceiling = int(EffectLevel::Gi);
    if (base.gather.overrideEffects) ceiling = std::min(ceiling, int(base.gather.effects));
    else if (base.gather.groupEffects[g] != kOwnEffectLevel) ceiling = std::min(ceiling, int(base.gather.groupEffects[g]));
    best_.levels[size_t(g)] = uint8_t(ceiling);
  }
  current_ = best_;
  // Every setting, when there are few enough to search one by one.
  size_t count = profile_.photonSides.size() * profile_.radiusScales.size() * profile_.denoiseIterations.size() *
                 (params_.foveationAvailable ? 2 : 1);
  for (int g = 0; g < groups_ && count <= kMaxExhaustive; ++g) count *= size_t(best_.levels[size_t(g)]) + 1;
  if (count <= kMaxExhaustive) {
    ControlSetting s;
    std::vector<ControlSetting> partial{s};
    auto expand = [&](auto assign, int n) {
      std::vector<ControlSetting> next;
      for (const ControlSetting& p : partial)
        for (int i = 0; i < n; ++i) next.push_back(p), assign(next.back(), i);
      partial = std::move(next);
    };
    expand([](ControlSetting& c, int i) { c.photons = i; }, int(profile_.photonSides.size()));
    expand([](ControlSetting& c, int i) { c.radius = i; }, int(profile_.radiusScales.size()));
    expand([](ControlSetting& c, int i) { c.denoise = i; }, int(profile_.denoiseIterations.size()));
    expand([](ControlSetting& c, int i) { c.foveated = i != 0; }, params_.foveationAvailable ? 2 : 1);
    for (int g = 0; g < groups_; ++g)
      expand([g](ControlSetting& c, int i) { c.levels[size_t(g)] = uint8_t(i); }, int(best_.levels[size_t(g)]) + 1);
    all_ = std::move(partial);
  }
}

bool BudgetController::hasGi(const ControlSetting& s) const {
  for (int g = 0; g < groups_; ++g)
    if (s.levels[size_t(g)] == uint8_t(EffectLevel::Gi)) return true;
  return false;
}

ControlCosts BudgetController::scaleOf(const ControlSetting& s) const {
  ControlCosts scale;
  // Without a group at gi nothing gathers photons: none are traced (FrameRenderer).
  const double side = hasGi(s) ? profile_.photonSides[size_t(s.photons)] : profile_.photonSides.front();
  const double photons = side * side / (double(profile_.photonSides.back()) * profile_.photonSides.back());  // of the top count
  const double r = profile_.radiusScales[size_t(s.radius)];
  const double samples = s.foveated ? profile_.foveatedSamples : 1.0;
  double giShare = 0, rays = 1.0;
  for (int g = 0; g < groups_; ++g) {
    const int level = s.levels[size_t(g)];
    if (level == int(EffectLevel::Gi)) giShare += profile_.densityShare[size_t(g)];
    rays += profile_.levelRayCost[size_t(g)][size_t(level)];
  }
  const double fp = profile_.photonFixedShare, fd = profile_.densityFixedShare;
  scale.photonMs = hasGi(s) ? fp + (1.0 - fp) * photons : 0.0;
  scale.densityMs = fd + (1.0 - fd) * photons * r * r * std::max(giShare, hasGi(s) ? kMinShare : 0.0) * samples;
  scale.rayMs = std::max(rays, kMinShare) * samples;
  scale.denoiseMs = profile_.denoisePasses(s.denoise);
  scale.restMs = 1.0;
  return scale;
}

double BudgetController::predictMs(const ControlSetting& s) const {
  if (units_.empty()) return 0.0;
  const ControlCosts scale = scaleOf(s);
  ControlCosts worst;
  for (const ControlCosts& u : units_) {
    worst.photonMs = std::max(worst.photonMs, u.photonMs);
    worst.densityMs = std::max(worst.densityMs, u.densityMs);
    worst.rayMs = std::max(worst.rayMs, u.rayMs);
    worst.denoiseMs = std::max(worst.denoiseMs, u.denoiseMs);
    worst.restMs = std::max(worst.restMs, u.restMs);
  }
  return worst.photonMs * scale.photonMs + worst.densityMs * scale.densityMs + worst.rayMs * scale.rayMs +
         worst.denoiseMs * scale.denoiseMs + worst.restMs * scale.restMs;
}

double BudgetController::predictError(const ControlSetting& s) const {
  double giShare = 0, e = profile_.topError + profile_.denoiseError[size_t(s.denoise)];
  for (int g = 0; g < groups_; ++g) {
    const int level = s.levels[size_t(g)];
    e += profile_.levelError[size_t(g)][size_t(level)];
    if (level == int(EffectLevel::Gi)) giShare += profile_.densityShare[size_t(g)];
  }
  // The photon knobs matter where photons are gathered, and more the less the denoiser filters.
  double photonTerms = profile_.photonError[size_t(s.photons)] + profile_.radiusError[size_t(s.radius)];
  if (const double w = profile_.undenoisedWeight(s.denoise); w > 0.0)
    photonTerms += w * (profile_.photonErrorUndenoised[size_t(s.photons)] + profile_.radiusErrorUndenoised[size_t(s.radius)] -
                        photonTerms);
  e += giShare * photonTerms;
  if (s.foveated) e += profile_.foveatedError;
  return std::max(e, 1e-9);
}

RenderOptions BudgetController::optionsFor(const ControlSetting& s) const {
  RenderOptions o = base_;
  const uint32_t side = hasGi(s) ? profile_.photonSides[size_t(s.photons)] : profile_.photonSides.front();
  o.photonsX = o.photonsY = side;
  o.gather.density.radius = base_.gather.density.radius * profile_.radiusScales[size_t(s.radius)];
  const int iterations = profile_.denoiseIterations[size_t(s.denoise)];
  o.denoise.enabled = iterations > 0;
  if (iterations > 0) {
    o.denoise.params.iterations = iterations;
    o.denoise.params.directIterations = profile_.denoiseDirectIterations[size_t(s.denoise)];
  }
  o.foveation.mask = s.foveated ? mask_ : nullptr;
  o.gather.overrideEffects = false;
  for (int g = 0; g < groups_; ++g) o.gather.groupEffects[g] = s.levels[size_t(g)];
  return o;
}

std::vector<ControlSetting> BudgetController::raisesOf(const ControlSetting& s) const {
  std::vector<ControlSetting> out;
  auto add = [&](ControlSetting n) {
    if (!(n == s)) out.push_back(n);
  };
  for (int d : {-1, 1}) {
    ControlSetting n = s;
    n.photons = std::clamp(s.photons + d, 0, int(profile_.photonSides.size()) - 1), add(n);
    n = s, n.radius = std::clamp(s.radius + d, 0, int(profile_.radiusScales.size()) - 1), add(n);
    n = s, n.denoise = std::clamp(s.denoise + d, 0, int(profile_.denoiseIterations.size()) - 1), add(n);
    for (int g = 0; g < groups_; ++g)
      n = s, n.levels[size_t(g)] = uint8_t(std::clamp(int(s.levels[size_t(g)]) + d, 0, int(best_.levels[size_t(g)]))), add(n);
  }
  if (params_.foveationAvailable) {
    ControlSetting n = s;
    n.foveated = !s.foveated, add(n);
  }
  return out;
}

void BudgetController::setBudget(double budgetMs) {
  if (budgetMs > 0.0 && finite(budgetMs) && budgetMs <= 10000.0) params_.budgetMs = budgetMs;
}

ControlDecision BudgetController::decide(double nowMs) {
  ControlDecision d;
  if (!started_) {
    // The first frame probes the view cheaply (the fewest photons, foveated, every group at its
    // ceiling so that each cost term is measured); the second takes the best setting that fits.
    started_ = true;
    current_ = best_;
    current_.photons = 0;
    current_.denoise = 0;
    current_.foveated = params_.foveationAvailable;
    d.change = "start";
  } else if (!settled_ && units_.size() < (params_.foveationAvailable ? 3u : 2u)) {
    // The probe again (a renderer's first frame pays for its allocations); then, where a mask
    // is available, at full resolution, for the foveated pass's time ratio at this view.
    if (params_.foveationAvailable && units_.size() == 2) current_.foveated = false;
    d.change = "start";
  } else if (!settled_) {
    settled_ = true;
    if (params_.foveationAvailable && measured_.size() >= 3 && measured_[1].second.foveated && !measured_[2].second.foveated)
      learnFoveatedRatio(foveatedRatioOf(measured_[1].first, measured_[1].second, measured_[2].first, measured_[2].second));
    units_.erase(units_.begin());
    measured_.erase(measured_.begin());
    while (units_.size() > size_t(params_.window)) units_.erase(units_.begin()), measured_.erase(measured_.begin());
    const double raiseLimit = params_.budgetMs * (1.0 - margin() - params_.raiseHeadroom);
    ControlSetting chosen = current_;
    double chosenError = std::numeric_limits<double>::infinity();
    auto consider = [&](const ControlSetting& c) {
      const double err = predictError(c);
      if (predictMs(c) <= raiseLimit && err < chosenError) chosen = c, chosenError = err;
    };
    if (!all_.empty()) {
      for (const ControlSetting& c : all_) consider(c);
    } else {
      consider(best_);
    }
    current_ = chosen;
    lastRaiseMs_ = nowMs;
    d.change = "start";
  } else if (!units_.empty()) {
    const double limit = params_.budgetMs * (1.0 - margin());
    const double raiseLimit = params_.budgetMs * (1.0 - margin() - params_.raiseHeadroom);
    const double predicted = predictMs(current_);
    if (predicted > limit) {
      // Lower at once, to the setting of least error that fits (the cheapest if none does).
      headroomFrames_ = 0;
      ControlSetting chosen = current_;
      double chosenError = std::numeric_limits<double>::infinity(), chosenMs = predicted;
      bool fits = false;
      auto consider = [&](const ControlSetting& c) {
        const double ms = predictMs(c);
        const bool f = ms <= limit;
        const double err = predictError(c);
        if ((f && (!fits || err < chosenError || (err == chosenError && ms < chosenMs))) || (!f && !fits && ms < chosenMs)) {
          chosen = c, chosenError = err, chosenMs = ms, fits = f;
        }
      };
      if (!all_.empty()) {
        for (const ControlSetting& c : all_) consider(c);
      } else {  // too many to search: greedy steps down, each the least error added per ms saved
        ControlSetting s = current_;
        for (int step = 0; step < 64 && predictMs(s) > limit; ++step) {
          const double ms = predictMs(s), err = predictError(s);
          double bestRatio = std::numeric_limits<double>::infinity();
          ControlSetting next = s;
          for (const ControlSetting& n : raisesOf(s)) {
            const double saved = ms - predictMs(n);
            if (saved <= 1e-9) continue;
            const double ratio = (predictError(n) - err) / saved;
            if (ratio < bestRatio) bestRatio = ratio, next = n;
          }
          if (next == s) break;
          s = next;
        }
        consider(s);
      }
      if (!(chosen == current_)) {
        // Over the limit it re-plans from every setting: the one that fits may be better elsewhere.
        d.change = predictError(chosen) < predictError(current_) ? "replan" : "lower";
        current_ = chosen;
      }
    } else {
      headroomFrames_ = predicted <= raiseLimit ? headroomFrames_ + 1 : 0;
      if (headroomFrames_ >= params_.holdFrames && nowMs - lastRaiseMs_ >= 1000.0 / params_.maxRaisesPerSecond) {
        const double err = predictError(current_);
        ControlSetting chosen = current_;
        double chosenGain = params_.minGain * err;
        // Settings within two knob steps: one knob up, or one up and one down (a trade, e.g. more
        // photons for a cheaper level elsewhere), so that the climb does not stop at a setting
        // whose single steps all cost too much.
        auto consider = [&](const ControlSetting& n) {
          const double gain = err - predictError(n);
          if (gain > chosenGain && predictMs(n) <= raiseLimit) chosen = n, chosenGain = gain;
        };
        const bool replan = !replanned_ && overruns_.size() >= 90 && !all_.empty();
        if (all_.empty()) {
          for (const ControlSetting& n : raisesOf(current_)) consider(n);
        } else {
          for (const ControlSetting& n : all_)
            if (replan || stepsBetween(current_, n, groups_) <= 2) consider(n);
        }
        replanned_ |= replan;
        if (!(chosen == current_)) {
          current_ = chosen;
          lastRaiseMs_ = nowMs;
          d.change = "raise";
        }
        headroomFrames_ = 0;  // found or not, the next search waits for `holdFrames` more
      }
    }
  }
  d.setting = current_;
  d.budgetMs = params_.budgetMs;
  d.predictedMs = predictMs(current_);
  d.predictedError = predictError(current_);
  lastPredictedMs_ = d.predictedMs;
  return d;
}

double BudgetController::margin() const {
  if (overruns_.size() < 90) return std::clamp(params_.startMargin, params_.margin, params_.maxMargin);
  const double worst = *std::max_element(overruns_.begin(), overruns_.end());
  return std::clamp(worst + 0.02, params_.margin, params_.maxMargin);
}

double BudgetController::foveatedRatioOf(const ControlCosts& foveated, const ControlSetting& foveatedSetting,
                                         const ControlCosts& full, const ControlSetting& fullSetting) const {
  // Each frame's eye rays over their scale without the foveated factor: the groups' levels may
  // differ between the two (at a switch; the start-up's probe frames differ in foveation alone).
  auto raysPerUnit = [&](double ms, ControlSetting s) {
    s.foveated = false;
    const double scale = scaleOf(s).rayMs;
    return scale > 0 ? ms / scale : 0.0;
  };
  const double a = raysPerUnit(foveated.rayMs, foveatedSetting), b = raysPerUnit(full.rayMs, fullSetting);
  return a > 0 && b > 0 ? a / b : 0.0;
}

void BudgetController::learnFoveatedRatio(double ratio) {
  if (!(ratio > 0.0) || !finite(ratio)) return;
  profile_.foveatedSamples = std::clamp(ratio, 0.01, 1.0);
  // The foveated frames' unit costs were divided by the old ratio. (The density-per-ray ratio
  // stays the newest frame's, not the last foveated one's.)
  const double densityPerRay = densityPerRay_;
  for (size_t i = 0; i < measured_.size(); ++i)
    if (measured_[i].second.foveated) unitFrom(units_[i], measured_[i].first, measured_[i].second);
  densityPerRay_ = densityPerRay;
}

void BudgetController::unitFrom(ControlCosts& unit, const ControlCosts& measured, const ControlSetting& s) {
  const ControlCosts scale = scaleOf(s);
  // A term that did not run this frame (scale 0) keeps what it was last measured at.
  auto update = [](double& u, double ms, double sc) {
    if (sc > 0) u = ms / sc;
  };
  update(unit.photonMs, measured.photonMs, scale.photonMs);
  update(unit.rayMs, measured.rayMs, scale.rayMs);
  // Density follows the view as the eye rays do: while nothing gathers (no group at gi) it is
  // carried at its last ratio to them, not at the value of a view long gone.
  if (scale.densityMs > 0) {
    update(unit.densityMs, measured.densityMs, scale.densityMs);
    if (unit.rayMs > 0) densityPerRay_ = unit.densityMs / unit.rayMs;
  } else if (densityPerRay_ >= 0) {
    unit.densityMs = densityPerRay_ * unit.rayMs;
  }
  update(unit.denoiseMs, measured.denoiseMs, scale.denoiseMs);
  update(unit.restMs, measured.restMs, scale.restMs);
}

void BudgetController::observe(const ControlCosts& measured) {
  // A switch between the foveated and the full-resolution pass from one frame to the next
  // measures their ratio again: the eye rays' time over their scale without the foveated factor
  // (the groups' levels may change with it). Two frames may also differ in view and noise, and the
  // level costs are modelled: the ratio moves at most 2x per switch, so one odd pair cannot set it
  // to where the controller would never switch again.
  bool remeasured = false;
  if (settled_ && !measured_.empty() && measured_.back().second.foveated != current_.foveated) {
    const auto& [beforeCosts, beforeSetting] = measured_.back();
    const double ratio = current_.foveated ? foveatedRatioOf(measured, current_, beforeCosts, beforeSetting)
                                           : foveatedRatioOf(beforeCosts, beforeSetting, measured, current_);
    if (ratio > 0) {
      const double old = profile_.foveatedSamples;
      learnFoveatedRatio(std::clamp(ratio, 0.5 * old, 2.0 * old));
      remeasured = true;
    }
  }
  // The frame's overrun against its prediction, unless that prediction used the ratio just
  // corrected (it would hold the margin high for a second after the model is right).
  if (lastPredictedMs_ > 0 && settled_ && !remeasured) {
    overruns_.push_back(measured.total() / lastPredictedMs_ - 1.0);
    if (overruns_.size() > 90) overruns_.erase(overruns_.begin());
  }
  ControlCosts unit = units_.empty() ? ControlCosts{} : units_.back();
  if (units_.empty()) unit.denoiseMs = profile_.denoiseMsPerIteration;
  unitFrom(unit, measured, current_);
  units_.push_back(unit);
  measured_.push_back({measured, current_});
  // While it probes, the probes' frames are all kept (the ratio needs the second and third).
  if (settled_ && units_.size() > size_t(params_.window)) units_.erase(units_.begin()), measured_.erase(measured_.begin());
}

nlohmann::json BudgetController::toJson(const ControlSetting& s, const ControlProfile& profile) {
  nlohmann::json levels = nlohmann::json::object();
  for (size_t g = 0; g < profile.groups.size(); ++g) levels[profile.groups[g]] = effectLevelName(EffectLevel(s.levels[g]));
  return {{"photons", profile.photonSides[size_t(s.photons)]},
          {"radius_scale", profile.radiusScales[size_t(s.radius)]},
          {"denoise_iterations", profile.denoiseIterations[size_t(s.denoise)]},
          {"denoise_direct_iterations", profile.denoiseDirectIterations[size_t(s.denoise)]},
          {"foveated", s.foveated},
          {"levels", levels}};
}

size_t ControlLog::framesOver(double budgetMs) const {
  return size_t(std::count_if(entries_.begin(), entries_.end(), [&](const ControlLogEntry& e) { return e.frameMs > budgetMs; }));
}

size_t ControlLog::framesOverTheirBudget() const {
  return size_t(std::count_if(entries_.begin(), entries_.end(),
                              [](const ControlLogEntry& e) { return e.frameMs > e.decision.budgetMs; }));
}

bool ControlLog::budgetChanged() const {
  return std::any_of(entries_.begin(), entries_.end(),
                     [&](const ControlLogEntry& e) { return e.decision.budgetMs != entries_.front().decision.budgetMs; });
}

size_t ControlLog::changes() const {
  return size_t(std::count_if(entries_.begin(), entries_.end(), [](const ControlLogEntry& e) {
    const std::string c = e.decision.change;
    return c == "lower" || c == "raise" || c == "replan";
  }));
}

nlohmann::json ControlLog::toJson(const BudgetController& controller) const {
  const double budget = controller.params().budgetMs;
  std::vector<double> ms;
  nlohmann::json frames = nlohmann::json::array();
  const bool perFrameBudget = budgetChanged();
  for (const ControlLogEntry& e : entries_) {
    ms.push_back(e.frameMs);
    nlohmann::json f = {{"ms", e.frameMs},
                        {"predicted_ms", e.decision.predictedMs},
                        {"predicted_error", e.decision.predictedError},
                        {"change", e.decision.change},
                        {"setting", BudgetController::toJson(e.decision.setting, controller.profile())},
                        {"costs_ms", {{"photons", e.costs.photonMs}, {"density", e.costs.densityMs}, {"eye_rays", e.costs.rayMs},
                                      {"denoise", e.costs.denoiseMs}, {"rest", e.costs.restMs}}}};
    if (e.measuredError >= 0) f["measured_error"] = e.measuredError;
    if (perFrameBudget) f["budget_ms"] = e.decision.budgetMs;
    frames.push_back(std::move(f));
  }
  return {{"budget_ms", budget},
          {"margin_min", controller.params().margin},
          {"margin_at_end", controller.currentMargin()},
          {"foveated_ratio_at_end", controller.foveatedRatio()},
          {"profile", controller.profile().scene},
          {"frame_ms", latencyStats(std::move(ms))},
          {"frames_over_budget", framesOverTheirBudget()},
          {"changes", changes()},
          {"frames", std::move(frames)}};
}

std::string ControlLog::summary(const BudgetController& controller) const {
  const double budget = controller.params().budgetMs;
  std::vector<double> ms, err;
  for (const ControlLogEntry& e : entries_) ms.push_back(e.frameMs), err.push_back(e.decision.predictedError);
  const LatencyStats t = latencyStats(std::move(ms)), e = latencyStats(std::move(err));
  char line[256];
  std::snprintf(line, sizeof line,
                "  controller: budget %.2f ms, frame p50 %.3f p99 %.3f ms, %zu of %zu frames over, %zu changes, "
                "predicted relMSE mean %.4f\n",
                budget, t.p50, t.p99, framesOverTheirBudget(), entries_.size(), changes(), e.mean);
  return line;
}

}  // namespace pvr
