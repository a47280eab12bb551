#pragma once
// The second pass of photon mapping: the radiance arriving at the eye along one pixel's ray,
// written once for any Intersector (`intersect`, `occluded`) and any photon map.
//
// The ray follows mirrors and glass (a specular chain) to the first diffuse surface (or a
// microfacet surface's gathered lobes: traceToGatherPoint). There:
//  - ShadingMode::Full: emission + direct light by one shadow ray to a light sample + caustic and
//    indirect light from the photon map (which then holds no direct, L D, photons);
//  - ShadingMode::PhotonMapOnly: emission + everything else from the photon map (the main paper's
//    formulation; the map then holds every photon including the direct ones).
#include "pvr/camera/stereo_rig.h"
#include "pvr/photon/boundary.h"
#include "pvr/photon/density.h"
#include "pvr/shading/primary_hits.h"
#include "pvr/shading/scene_view.h"
#include "pvr/stereo/stereo_reuse.h"
#include "pvr/util/rng.h"

namespace pvr {

enum class ShadingMode : int { Full = 0, PhotonMapOnly = 1 };

// How a pixel draws its first random numbers (its sub-pixel position and first light sample).
enum class PixelSampling : uint8_t {
  White = 0,      ///< independent hashed numbers (the reference's passes)
  BlueNoise = 1,  ///< blue-noise dithered, low-discrepancy over a run of frames (util/blue_noise.h)
};

struct GatherParams {
  DensityParams density;
  ShadingMode mode = ShadingMode::Full;
  int maxSpecularDepth = 8;  ///< mirror/glass bounces followed from the eye
  int samplesPerPixel = 1;
  // Shadow rays to the point and spot lights per gather point, each to one light chosen by its
  // unoccluded contribution (punctualDirectLight; distant lights get a ray each); 0: one exact
  // ray to every light.
  int punctualShadowRays = 1;
  bool jitterFirstSample = false;  ///< false: sample 0 through the pixel centre (a stable first hit)
  uint32_t seed = 1;
  PixelSampling sampling = PixelSampling::BlueNoise;
  // The frame's number in a run of frames that blend (TAA, the denoiser, a still head's
  // refinement): each pixel's samples go on along their sequences, and the photons and hashed
  // numbers are new every frame. 0: a frame on its own.
  uint32_t sequenceIndex = 0;
  // Sample 0's first hits found before the eye pass, set by the backend for one eye pass: traced
  // by a pre-pass (any sample position), or rasterised (the G-buffer pre-pass; ignored when the
  // first sample is jittered); none: traced in place.
  PrimaryHitsView primary;
  // Every material's effect level replaced by `effects`; else its group's level where that is
  // set (not kOwnEffectLevel), else the surface's own (Material::effect).
  bool overrideEffects = false;
  EffectLevel effects = EffectLevel::Gi;
  uint8_t groupEffects[kMaxEffectGroups] = {kOwnEffectLevel, kOwnEffectLevel, kOwnEffectLevel, kOwnEffectLevel,
                                            kOwnEffectLevel, kOwnEffectLevel, kOwnEffectLevel, kOwnEffectLevel};
  int pathDepth = 8;  ///< EffectLevel::Path: bounces of its indirect paths (Russian roulette after 3)
};

// The effect level the eye paths use at a surface of material m.
PVR_HOST_DEVICE inline EffectLevel effectLevelOf(const GatherParams& params, const Material& m) {
  if (params.overrideEffects) return params.effects;
  const uint8_t group = params.groupEffects[m.effectGroup];
  return group == kOwnEffectLevel ? m.effect : EffectLevel(group);
}

// Shadow rays that always reach their light: EffectLevel::Raster's direct light.
struct NoOccluders {
  PVR_HOST_DEVICE bool occluded(const Ray&, float) const { return false; }
};

// One pixel's result. Sample 0 (the centre ray) decides everything but the radiance.
struct PixelSample {
  Vec3 radiance{0, 0, 0};
  uint32_t firstPrim = ~0u;          ///< triangle seen first by the pixel's centre sample, ~0u for none
  float inverseDepth = 0.0f;         ///< 1 / view depth of that first hit (EyeCamera::inverseDepthOf), 0 for none
  uint32_t reusedFrom = kNotReused;  ///< the other eye's pixel whose shading this pixel took
};

// Where an eye path ends on a surface that gathers from the photon map, with everything gathered
// on the way except the photon-map estimate there: radiance = emitted + direct light, and the
// estimate still to add is weight * estimateFluxDensity(position, normal, photonContribution).
// Splitting here is what lets the GPU trace eye rays in one kernel and estimate densities in
// another (the paper's hybrid scheme).
//
// On a Lambertian surface (lobes == 0) every photon counts by its power and weight is
// throughput * albedo / pi. On a microfacet surface the BSDF's gathered lobes are evaluated for
// each photon's direction (view-dependent), and weight is the path's throughput.
struct GatherPoint {
  Vec3 radiance{0, 0, 0};
  Vec3 emitted{0, 0, 0};  ///< the part of radiance emitted along the path (lights, sky seen): no noise
  Vec3 weight{0, 0, 0};  ///< zero when the path found no surface to gather on
  Vec3 position{0, 0, 0};
  Vec3 normal{0, 0, 0};  ///< geometric normal facing the arriving ray
  uint32_t lobes = 0;    ///< the BSDF lobes the estimate evaluates; 0: Lambertian, none evaluated
  Vec3 wo{0, 0, 0};      ///< towards where the path came from (lobes != 0)
  BsdfParams bsdf;       ///< (lobes != 0)
  Vec3 wall{0, 0, 0};    ///< Boundary::Clipped: the nearest wall, whose photons the estimate leaves out (photonCounts)
  // What the denoiser divides the pixel by, so that it filters irradiance rather than texture:
  // the path's reflectance towards the eye (throughput times albedo; the base colour on a
  // microfacet surface), at every effect level (below Gi weight is zero, but the texture is
  // there all the same). Zero where the path found no surface.
  Vec3 reflectance{0, 0, 0};
  PVR_HOST_DEVICE bool needsEstimate() const { return !isBlack(weight); }
  // What a photon that reached the surface adds to the estimate before `weight` and 1 / (pi r^2).
  PVR_HOST_DEVICE Vec3 photonContribution(const Photon& p) const {
    return lobes == 0 ? p.power : bsdf.eval(wo, -p.direction, lobes) * p.power;
  }
};

// What the denoiser needs of a pixel besides its radiance: its emitted part (lights and sky seen,
// which it leaves alone) and its direct part (emission and shadow rays; the rest came from the
// photon map), both the mean over its samples, and sample 0's demodulation albedo and
// gather-surface normal (zero: none).
struct PixelGuide {
  Vec3 emitted{0, 0, 0};
  Vec3 direct{0, 0, 0};
  Vec3 albedo{0, 0, 0};
  Vec3 normal{0, 0, 0};
};

// What a punctual light would add at a surface point if its shadow ray is unblocked.
struct ShadowedContribution {
  Vec3 value{0, 0, 0};
  Ray shadow{};
  float distance = 0.0f;
};

// Light k's unoccluded contribution f E |cos| at a point. `bsdf` gives f(wi) for a direction to
// the light; `twoSided` lets light arrive from behind (transmission).
template <class Bsdf>
PVR_HOST_DEVICE ShadowedContribution punctualContribution(const SceneView& scene, uint32_t k, Vec3 position, Vec3 nGeo,
                                                          Vec3 nShade, bool twoSided, float eps, const Bsdf& bsdf) {
  ShadowedContribution c;
  LightSample ls;
  ls.punctual = int(k);
  ls.pick = 1.0f;
  PunctualIllumination li = illuminate(scene, ls, position, eps);
  float cosSurface = dot(nShade, li.wi), cosGeometric = dot(nGeo, li.wi);
  bool front = cosSurface > 0.0f && cosGeometric > 0.0f;
  bool back = twoSided && cosSurface < 0.0f && cosGeometric < 0.0f;
  if ((!front && !back) || isBlack(li.irradiance)) return c;
  c.value = bsdf(li.wi) * li.irradiance * fabsf(cosSurface);
  c.shadow = Ray{position + (front ? nGeo : -nGeo) * eps, li.wi};
  c.distance = li.shadowDistance;
  return c;
}

// Direct light from the point, spot and distant lights at a surface point. Each distant light
// (the sun) gets one exact shadow ray: it dominates where it shines and is hidden wholesale where
// it does not (a nave under a roof), which a choice made without visibility would sample as often
// either way. Among the point and spot lights, each of the shadowRays rays goes to one light chosen
// in proportion to the luminance of its unoccluded contribution here (its power and solid angle,
// the cosine and the BSDF): unbiased, and exact in luminance wherever those lights are visible, so
// the noise is their visibility's and their hues'. With shadowRays == 0, or at least one ray per
// light, every light gets one exact ray. The choice is one weighted-reservoir pass over the lights
// with one random number, so nothing is stored per light.
template <class Intersector, class Bsdf>
PVR_HOST_DEVICE Vec3 punctualDirectLight(const SceneView& scene, const Intersector& intersector, Vec3 position,
                                         Vec3 nGeo, Vec3 nShade, bool twoSided, float eps, const Bsdf& bsdf,
                                         int shadowRays, CounterRng& rng) {
  Vec3 sum{0, 0, 0};
  uint32_t localCount = 0;
  for (uint32_t k = 0; k < scene.punctualCount; ++k) localCount += scene.punctualLights[k].kind != PunctualKind::Directional;
  const bool chooseLocal = shadowRays > 0 && uint32_t(shadowRays) < localCount;
  for (uint32_t k = 0; k < scene.punctualCount; ++k) {
    if (chooseLocal && scene.punctualLights[k].kind != PunctualKind::Directional) continue;
    ShadowedContribution c = punctualContribution(scene, k, position, nGeo, nShade, twoSided, eps, bsdf);
    if (!isBlack(c.value) && !intersector.occluded(c.shadow, c.distance)) sum += c.value;
  }
  if (!chooseLocal) return sum;
  Vec3 chosenSum{0, 0, 0};
  for (int s = 0; s < shadowRays; ++s) {
    float u = rng.uniform();
    float total = 0.0f, chosenWeight = 0.0f;
    ShadowedContribution chosen;
    for (uint32_t k = 0; k < scene.punctualCount; ++k) {
      if (scene.punctualLights[k].kind == PunctualKind::Directional) continue;
      ShadowedContribution c = punctualContribution(scene, k, position, nGeo, nShade, twoSided, eps, bsdf);
      float w = luminance(c.value);
      if (!(w > 0.0f)) continue;
      total += w;
      float p = w / total;
      if (u < p) {  // take light k; u, rescaled, stays uniform for the lights after it
        chosen = c, chosenWeight = w;
        u = u / p;
      } else {
        u = (u - p) / (1.0f - p);
      }
    }
    if (chosenWeight > 0.0f && !intersector.occluded(chosen.shadow, chosen.distance))
      chosenSum += chosen.value * (total / chosenWeight);
  }
  return sum + chosenSum * (1.0f / float(shadowRays));
}

// The shadow rays diffuseDirectLight asks at a Lambertian point that faces every light: one per
// distant light, `shadowRays` among the local ones (or one per local light where that is fewer, or
// shadowRays is 0), one for the area lights and one for the sky. (A microfacet point asks only the
// punctual lights'; mirrors and glass ask none.)
PVR_HOST_DEVICE inline int shadowQueriesPerPoint(const SceneView& scene, int shadowRays) {
  int distant = 0, local = 0;
  for (uint32_t k = 0; k < scene.punctualCount; ++k)
    (scene.punctualLights[k].kind == PunctualKind::Directional ? distant : local) += 1;
  const bool chooseLocal = shadowRays > 0 && shadowRays < local;
  return distant + (chooseLocal ? shadowRays : local) + (scene.triangleLightCount > 0 ? 1 : 0) +
         (scene.sky.present() ? 1 : 0);
}

// One sample of the area lights' direct light at a surface point (front side only).
template <class Intersector, class Bsdf>
PVR_HOST_DEVICE Vec3 areaDirectLight(const SceneView& scene, const Intersector& intersector, Vec3 position, Vec3 nGeo,
                                     Vec3 nShade, float eps, CounterRng& rng, const Bsdf& bsdf) {
  float uPick = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
  LightSample ls = sampleAreaLight(scene, uPick, u1, u2);
  Vec3 toLight = ls.position - position;
  float dist2 = lengthSquared(toLight);
  float dist = sqrtf(dist2);
  Vec3 wi = toLight / dist;
  float cosSurface = dot(nShade, wi), cosLight = -dot(ls.normal, wi);
  if (!(cosSurface > 0.0f && cosLight > 0.0f && dot(nGeo, wi) > 0.0f)) return {0, 0, 0};
  Ray shadow{position + nGeo * eps, wi};
  if (intersector.occluded(shadow, dist * (1.0f - 1e-3f) - eps)) return {0, 0, 0};
  return bsdf(wi) * ls.emission * (cosSurface * cosLight / (dist2 * ls.pdfArea));
}

// One cosine-weighted sample of the sky's direct light at a surface point (front side only):
// f L pi where the shadow ray escapes upwards.
template <class Intersector, class Bsdf>
PVR_HOST_DEVICE Vec3 skyDirectLight(const SceneView& scene, const Intersector& intersector, Vec3 position, Vec3 nGeo,
                                    Vec3 nShade, float eps, CounterRng& rng, const Bsdf& bsdf) {
  // Two statements: the order of evaluation of arguments differs between g++ and nvcc.
  float u1 = rng.uniform();
  float u2 = rng.uniform();
  Vec3 wi = Frame::fromNormal(nShade).toWorld(sampleCosineHemisphere(u1, u2));
  if (!(wi.y > 0.0f) || !(dot(nGeo, wi) > 0.0f)) return {0, 0, 0};
  if (intersector.occluded(Ray{position + nGeo * eps, wi}, INFINITY)) return {0, 0, 0};
  return bsdf(wi) * scene.sky.radiance * kPi;
}

// Direct light at a Lambertian surface point: the punctual, area and sky lights' estimators, in
// that order (the random numbers are drawn the same way at every effect level).
template <class Intersector, class Bsdf>
PVR_HOST_DEVICE Vec3 diffuseDirectLight(const SceneView& scene, const Intersector& intersector, const GatherParams& params,
                                        Vec3 position, Vec3 nGeo, Vec3 nShade, float eps, const Bsdf& bsdf,
                                        CounterRng& rng) {
  Vec3 sum = punctualDirectLight(scene, intersector, position, nGeo, nShade, false, eps, bsdf, params.punctualShadowRays, rng);
  if (scene.triangleLightCount > 0) sum += areaDirectLight(scene, intersector, position, nGeo, nShade, eps, rng, bsdf);
  if (scene.sky.present()) sum += skyDirectLight(scene, intersector, position, nGeo, nShade, eps, rng, bsdf);
  return sum;
}

// EffectLevel::Path's indirect light: the radiance arriving along `ray` (leaving a surface whose
// direct light was estimated by shadow rays) from a path traced onwards. Each diffuse or glossy
// vertex adds its direct light by the shadow-ray estimators (next-event estimation), so emission
// the path finds counts only after a mirror or glass bounce. Russian roulette after 3 bounces.
// Not inlined on the GPU: every eye kernel calls it, few frames take it. (It does not set the
// kernels' register count: 192 either way on the H200, against 159 before the effect levels.)
template <class Intersector>
PVR_HOST_DEVICE PVR_NOINLINE Vec3 pathTracedRadiance(const SceneView& scene, const Intersector& intersector, const GatherParams& params,
                                        Ray ray, CounterRng& rng) {
  Vec3 sum{0, 0, 0}, throughput{1, 1, 1};
  const float eps = scene.rayEpsilon();
  bool countEmission = false;
  for (int bounce = 0; bounce < params.pathDepth; ++bounce) {
    Hit hit;
    intersector.intersect(ray, INFINITY, hit);
    if (!hit.valid()) {
      if (countEmission) sum += throughput * scene.sky.along(ray.dir);
      break;
    }
    const SurfacePoint sp = scene.surfacePoint(hit);
    const Material& m = scene.materials[sp.materialId];
    const float cosIn = dot(ray.dir, sp.geometricNormal);
    const bool front = cosIn < 0.0f;
    if (countEmission && front && m.isEmissive())
      sum += throughput * scene.emissionAt(m, hit.primId, hit.u, hit.v, 0.0f, cosIn);
    const Vec3 nGeo = front ? sp.geometricNormal : -sp.geometricNormal;
    if (m.type == MaterialType::Diffuse) {
      const Vec3 nShade = front ? sp.shadingNormal : -sp.shadingNormal;
      const Vec3 albedo = scene.albedoAt(m, hit.primId, hit.u, hit.v, 0.0f, dot(ray.dir, nGeo));
      const Vec3 brdf = albedo * kInvPi;
      sum += throughput * diffuseDirectLight(scene, intersector, params, sp.position, nGeo, nShade, eps,
                                             [&](Vec3) { return brdf; }, rng);
      // Two statements: the order of evaluation of arguments differs between g++ and nvcc.
      float u1 = rng.uniform();
      float u2 = rng.uniform();
      const Vec3 wi = Frame::fromNormal(nShade).toWorld(sampleCosineHemisphere(u1, u2));
      if (!(dot(wi, nGeo) > 0.0f)) break;
      throughput *= albedo;  // f cos / pdf of cosine sampling
      ray = Ray{sp.position + nGeo * eps, wi};
      countEmission = false;
    } else if (m.type == MaterialType::Microfacet) {
      const Vec3 wo = -ray.dir;
      const BsdfParams b = scene.bsdfAt(m, hit, sp, wo, 0.0f);
      auto bsdf = [&](Vec3 wi) { return b.eval(wo, wi); };
      sum += throughput * punctualDirectLight(scene, intersector, sp.position, nGeo, b.normal, m.transmits(), eps, bsdf,
                                              params.punctualShadowRays, rng);
      if (scene.triangleLightCount > 0)
        sum += throughput * areaDirectLight(scene, intersector, sp.position, nGeo, b.normal, eps, rng, bsdf);
      if (scene.sky.present())
        sum += throughput * skyDirectLight(scene, intersector, sp.position, nGeo, b.normal, eps, rng, bsdf);
      // Three statements: the order of evaluation of arguments differs between g++ and nvcc.
      float uLobe = rng.uniform();
      float u1 = rng.uniform();
      float u2 = rng.uniform();
      const BsdfSample bs = sampleBsdf(b, wo, uLobe, u1, u2);
      if (!bs.valid()) break;
      throughput *= bs.weight;
      ray.dir = bs.wi;
      ray.origin = sp.position + (dot(bs.wi, sp.geometricNormal) > 0.0f ? sp.geometricNormal : -sp.geometricNormal) * eps;
      // The area and sky estimators see the front side only: what a transmitted ray finds, they missed.
      countEmission = dot(bs.wi, nGeo) < 0.0f;
    } else {
      ray.dir = scatterSpecular(m, ray.dir, sp.shadingNormal, rng.uniform(), throughput);
      ray.origin = sp.position + (dot(ray.dir, sp.geometricNormal) > 0.0f ? sp.geometricNormal : -sp.geometricNormal) * eps;
      countEmission = true;  // a delta bounce: no shadow ray counted what it finds
    }
    if (bounce >= 2) {
      const float survive = fminf(0.95f, maxComponent(throughput));
      if (!(rng.uniform() < survive)) break;
      throughput *= 1.0f / survive;
    }
  }
  return sum;
}

// Boundary::Clipped: the point's estimate cut at the nearest wall and scaled by the share of its disc
// that lies on the surface (photon/boundary.h; kNN takes the cut alone).
template <class Intersector>
PVR_HOST_DEVICE void clipAtBoundaries(const SceneView& scene, const Intersector& intersector, const GatherParams& params,
                                 GatherPoint& point, CounterRng& rng) {
  if (params.density.boundary != Boundary::Clipped || !point.needsEstimate()) return;
  const WallProbe probe = probeWalls(scene, intersector, point.position, point.normal, params.density.radius, rng.uniform());
  point.wall = probe.wall;
  if (params.density.estimator != Estimator::Radius) return;
  point.weight *= 1.0f / probe.discShare;
}

// Follows the eye ray through mirrors and glass to a surface that gathers from the photon map.
// `firstHit`, if given, is the ray's first intersection, already traced. `coneSpread` is the ray
// cone's width per unit distance (a pixel's, for camera rays): it chooses the textures' level of
// detail, and grows along the path (mirrors and glass are flat).
//
// On a microfacet surface the lobes split: transmission, and reflection sharper than
// kGatheredMinAlpha, are followed by sampling the BSDF; the rest (diffuse, rough reflection) is
// gathered there: direct light by shadow rays, the rest from the photon map with the BSDF. One
// random choice between the two, by the lobes' probabilities, keeps one gather point per path and
// is unbiased. Punctual lights are evaluated with the whole BSDF at every such surface.
//
// The surface's effect level (effectLevelOf) trims this: below Reflections nothing is followed
// (mirrors and glass are shaded as Lambertian surfaces of their tint), Raster's direct light casts
// no shadows, only Gi leaves an estimate to the photon map, and Path traces the indirect light.
// Below Gi the point carries no estimate (weight zero) even under ShadingMode::PhotonMapOnly,
// whose direct light then comes from shadow rays.
template <class Intersector>
PVR_HOST_DEVICE GatherPoint traceToGatherPoint(const SceneView& scene, const Intersector& intersector,
                                               const GatherParams& params, Ray ray, CounterRng& rng,
                                               const Hit* firstHit = nullptr, float coneSpread = 0.0f) {
  GatherPoint out;
  Vec3 throughput{1, 1, 1};
  float eps = scene.rayEpsilon();
  float coneWidth = 0.0f;
  const bool full = params.mode == ShadingMode::Full;
  for (int depth = 0; depth <= params.maxSpecularDepth; ++depth) {
    Hit hit;
    if (depth == 0 && firstHit) hit = *firstHit;
    else intersector.intersect(ray, INFINITY, hit);
    if (!hit.valid()) {  // escaped: the sky (never reached this way from a gather point)
      const Vec3 sky = throughput * scene.sky.along(ray.dir);
      out.radiance += sky;
      out.emitted += sky;
      break;
    }
    coneWidth += coneSpread * hit.t;
    SurfacePoint sp = scene.surfacePoint(hit);
    const Material& m = scene.materials[sp.materialId];
    bool front = dot(ray.dir, sp.geometricNormal) < 0.0f;
    if (front && m.isEmissive()) {
      const Vec3 e = throughput * scene.emissionAt(m, hit.primId, hit.u, hit.v, coneWidth, dot(ray.dir, sp.geometricNormal));
      out.radiance += e;
      out.emitted += e;
    }
    Vec3 nGeo = front ? sp.geometricNormal : -sp.geometricNormal;
    const EffectLevel level = effectLevelOf(params, m);
    const bool direct = full || level != EffectLevel::Gi;  // photon-map-only Gi leaves direct light to the map
    const bool unshadowed = level == EffectLevel::Raster;
    const bool followNothing = level < EffectLevel::Reflections;
    if (m.type == MaterialType::Diffuse || (m.isSpecular() && followNothing)) {
      Vec3 nShade = front ? sp.shadingNormal : -sp.shadingNormal;
      const Vec3 albedo = m.type == MaterialType::Diffuse
                              ? scene.albedoAt(m, hit.primId, hit.u, hit.v, coneWidth, dot(ray.dir, nGeo))
                              : m.albedo;
      Vec3 brdf = albedo * kInvPi;
      auto lambertian = [&](Vec3) { return brdf; };
      if (direct && unshadowed)
        out.radiance += throughput * diffuseDirectLight(scene, NoOccluders(), params, sp.position, nGeo, nShade, eps, lambertian, rng);
      else if (direct)
        out.radiance += throughput * diffuseDirectLight(scene, intersector, params, sp.position, nGeo, nShade, eps, lambertian, rng);
      out.reflectance = throughput * albedo;
      if (level == EffectLevel::Gi) {
        const float occlusion = scene.occlusionAt(m, hit.primId, hit.u, hit.v, coneWidth, dot(ray.dir, nGeo));
        out.weight = throughput * brdf * occlusion;
        out.reflectance *= occlusion;
      }
      if (level == EffectLevel::Path) {
        // Two statements: the order of evaluation of arguments differs between g++ and nvcc.
        float u1 = rng.uniform();
        float u2 = rng.uniform();
        const Vec3 wi = Frame::fromNormal(nShade).toWorld(sampleCosineHemisphere(u1, u2));
        if (dot(wi, nGeo) > 0.0f)  // f cos / pdf of cosine sampling: the albedo
          out.radiance += throughput * albedo * pathTracedRadiance(scene, intersector, params, Ray{sp.position + nGeo * eps, wi}, rng);
      }
      out.position = sp.position;
      out.normal = nGeo;
      clipAtBoundaries(scene, intersector, params, out, rng);
      break;
    }
    if (m.type == MaterialType::Microfacet) {
      const Vec3 wo = -ray.dir;
      const BsdfParams b = scene.bsdfAt(m, hit, sp, wo, coneWidth);
      auto bsdf = [&](Vec3 wi) { return b.eval(wo, wi); };
      if (direct && unshadowed)
        out.radiance += throughput * punctualDirectLight(scene, NoOccluders(), sp.position, nGeo, b.normal, m.transmits(), eps,
                                                         bsdf, params.punctualShadowRays, rng);
      else if (direct)
        out.radiance += throughput * punctualDirectLight(scene, intersector, sp.position, nGeo, b.normal, m.transmits(), eps,
                                                         bsdf, params.punctualShadowRays, rng);
      const uint32_t followed =
          followNothing ? 0u : kLobeTransmission | (b.alpha < kGatheredMinAlpha ? uint32_t(kLobeReflection) : 0u);
      float p[3];
      b.lobeProbabilities(dot(b.normal, wo), kLobesAll, p);
      const float pFollow = ((followed & kLobeReflection) ? p[1] : 0.0f) + ((followed & kLobeTransmission) ? p[2] : 0.0f);
      bool follow = pFollow >= 1.0f;
      if (pFollow > 0.0f && pFollow < 1.0f) follow = rng.uniform() < pFollow;
      if (!follow) {
        const uint32_t gathered = kLobesAll & ~followed;
        const Vec3 scale = throughput * (1.0f / (1.0f - pFollow));
        auto gatheredBsdf = [&](Vec3 wi) { return b.eval(wo, wi, gathered); };
        if (direct && unshadowed) {
          if (scene.triangleLightCount > 0)
            out.radiance += scale * areaDirectLight(scene, NoOccluders(), sp.position, nGeo, b.normal, eps, rng, gatheredBsdf);
          if (scene.sky.present())
            out.radiance += scale * skyDirectLight(scene, NoOccluders(), sp.position, nGeo, b.normal, eps, rng, gatheredBsdf);
        } else if (direct) {
          if (scene.triangleLightCount > 0)
            out.radiance += scale * areaDirectLight(scene, intersector, sp.position, nGeo, b.normal, eps, rng, gatheredBsdf);
          if (scene.sky.present())
            out.radiance += scale * skyDirectLight(scene, intersector, sp.position, nGeo, b.normal, eps, rng, gatheredBsdf);
        }
        if (level == EffectLevel::Path) {
          // Three statements: the order of evaluation of arguments differs between g++ and nvcc.
          float uLobe = rng.uniform();
          float u1 = rng.uniform();
          float u2 = rng.uniform();
          const BsdfSample bs = sampleBsdf(b, wo, uLobe, u1, u2, gathered);
          if (bs.valid()) {
            const Vec3 side = dot(bs.wi, sp.geometricNormal) > 0.0f ? sp.geometricNormal : -sp.geometricNormal;
            out.radiance += scale * bs.weight * pathTracedRadiance(scene, intersector, params, Ray{sp.position + side * eps, bs.wi}, rng);
          }
        }
        out.reflectance = scale * b.baseColor;
        if (level == EffectLevel::Gi) {
          const float occlusion = scene.occlusionAt(m, hit.primId, hit.u, hit.v, coneWidth, -dot(wo, nGeo));
          out.weight = scale * occlusion;
          out.reflectance *= occlusion;
        }
        out.position = sp.position;
        out.normal = nGeo;
        out.lobes = gathered;
        out.wo = wo;
        out.bsdf = b;
        clipAtBoundaries(scene, intersector, params, out, rng);
        break;
      }
      // Three statements: the order of evaluation of arguments differs between g++ and nvcc.
      float uLobe = rng.uniform();
      float u1 = rng.uniform();
      float u2 = rng.uniform();
      BsdfSample bs = sampleBsdf(b, wo, uLobe, u1, u2, followed);
      if (!bs.valid()) break;
      throughput *= bs.weight * (1.0f / pFollow);
      ray.dir = bs.wi;
    } else {
      ray.dir = scatterSpecular(m, ray.dir, sp.shadingNormal, rng.uniform(), throughput);
    }
    Vec3 side = dot(ray.dir, sp.geometricNormal) > 0.0f ? sp.geometricNormal : -sp.geometricNormal;
    ray.origin = sp.position + side * eps;
  }
  return out;
}

// Adds the photon-map estimate at the gather point.
template <class PhotonMap>
PVR_HOST_DEVICE Vec3 finishGather(const PhotonMap& map, const GatherPoint& point, const DensityParams& density) {
  if (!point.needsEstimate()) return point.radiance;
  auto contribution = [&](const Photon& p) { return point.photonContribution(p); };
  return point.radiance +
         point.weight * estimateFluxDensity(map, point.position, point.normal, density, contribution, point.wall);
}

// Radiance arriving along one eye ray.
template <class Intersector, class PhotonMap>
PVR_HOST_DEVICE Vec3 radianceAlongRay(const SceneView& scene, const Intersector& intersector, const PhotonMap& map,
                                      const GatherParams& params, Ray ray, CounterRng& rng) {
  return finishGather(map, traceToGatherPoint(scene, intersector, params, ray, rng), params.density);
}

// The random numbers of sample s of stream `stream` (a pixel's index, or an image position's
// hash) of one eye: hashed.
PVR_HOST_DEVICE inline CounterRng pixelRng(const GatherParams& params, Eye eye, uint32_t stream, int s) {
  uint32_t key = hashCombine(params.seed, 0x51ed270bu + uint32_t(eye));
  if (params.sequenceIndex) key = hashCombine(key, params.sequenceIndex);
  return CounterRng(key, stream, uint32_t(s));
}

// The random numbers of sample s of pixel (x, y) of one eye: the first ones blue noise, unless
// params.sampling says White. Frame k of a run is number k of the pixel's sequences for every
// sample; each sample and eye scrambles its own. (Numbering the samples k * spp + s instead
// would give sample s every spp-th Halton point: for a base dividing spp, a fixed part of
// [0, 1), and the centre sample uses its dimensions for the light, the others for jitter.)
PVR_HOST_DEVICE inline CounterRng pixelRng(const GatherParams& params, const EyeCamera& camera, Eye eye, int x, int y,
                                           int s) {
  CounterRng rng = pixelRng(params, eye, uint32_t(y) * uint32_t(camera.width) + uint32_t(x), s);
  if (params.sampling == PixelSampling::BlueNoise)
    rng.useBlueNoise(uint32_t(x), uint32_t(y), params.sequenceIndex,
                     hashCombine(hashCombine(params.seed, 0xb10e5u + uint32_t(eye)), uint32_t(s)));
  return rng;
}

// The camera ray of sample s of pixel (x, y), with the random numbers that continue its path. The
// first sample goes through the pixel centre, so the first-hit id is stable, unless
// params.jitterFirstSample (a reference's box filter).
PVR_HOST_DEVICE inline Ray pixelSampleRay(const GatherParams& params, const EyeCamera& camera, Eye eye, int x, int y,
                                          int s, CounterRng& rng) {
  rng = pixelRng(params, camera, eye, x, y, s);
  const bool centre = s == 0 && !params.jitterFirstSample;
  // Two statements: the order of evaluation of arguments differs between g++ and nvcc.
  float jx = centre ? 0.5f : rng.uniform();
  float jy = centre ? 0.5f : rng.uniform();
  return camera.generateRay(float(x) + jx, float(y) + jy);
}

// Sample 0's first hit of pixel (x, y), exactly as pixelGatherPoint traces it in place: what a
// first-hit pre-pass stores (PrimaryHitsView::traced).
template <class Intersector>
PVR_HOST_DEVICE Hit pixelFirstHit(const Intersector& intersector, const GatherParams& params, const EyeCamera& camera,
                                  Eye eye, int x, int y) {
  CounterRng rng(0, 0, 0);
  const Ray ray = pixelSampleRay(params, camera, eye, x, y, 0, rng);
  Hit first;
  intersector.intersect(ray, INFINITY, first);
  return first;
}

// The inverse view depth of a camera ray's first hit (0: none).
PVR_HOST_DEVICE inline float firstHitInverseDepth(const EyeCamera& camera, const Ray& ray, const Hit& first) {
  return first.valid() ? camera.inverseDepthOf(ray.origin + ray.dir * first.t) : 0.0f;
}

// The gather point seen through a continuous image position (a foveation mask's vertex), with the
// random numbers of the pixel it lies in: a vertex on a pixel centre is shaded exactly as that
// pixel's first sample. Positions outside the image get streams of their own. `inverseDepth`
// receives the first hit's (for temporal reprojection).
template <class Intersector>
PVR_HOST_DEVICE GatherPoint imagePositionGatherPoint(const SceneView& scene, const Intersector& intersector,
                                                     const GatherParams& params, const EyeCamera& camera, Eye eye,
                                                     float px, float py, float& inverseDepth) {
  int ix = int(floorf(px)), iy = int(floorf(py));
  bool inside = ix >= 0 && iy >= 0 && ix < camera.width && iy < camera.height;
  CounterRng rng = inside ? pixelRng(params, camera, eye, ix, iy, 0)
                          : pixelRng(params, eye, hashCombine(hashCombine(0x9e3779b9u, uint32_t(ix)), uint32_t(iy)) | 0x80000000u, 0);
  Ray ray = camera.generateRay(px, py);
  Hit first;
  intersector.intersect(ray, INFINITY, first);
  inverseDepth = firstHitInverseDepth(camera, ray, first);
  return traceToGatherPoint(scene, intersector, params, ray, rng, &first, camera.pixelSpread());
}

// Sample 0's first hit of pixel (x, y) along its `ray`: from the first-hit pre-pass or the raster
// G-buffer where the frame has one, else traced.
template <class Intersector>
PVR_HOST_DEVICE Hit sampleZeroFirstHit(const SceneView& scene, const Intersector& intersector,
                                       const GatherParams& params, int x, int y, const Ray& ray) {
  Hit first;
  if (params.primary.traced)
    first = params.primary.traced[size_t(y) * size_t(params.primary.width) + size_t(x)];
  else if (!params.primary.present() || params.jitterFirstSample ||
           !rasterisedFirstHit(scene, params.primary, x, y, ray, first))
    intersector.intersect(ray, INFINITY, first);
  return first;
}

// What sample 0's first hit decides for its pixel: its id and inverse depth, under gather reuse
// the other eye's pixel it reuses (or kNotReused), and its surface record in `surfaceOut` if given.
PVR_HOST_DEVICE inline void recordFirstHit(const SceneView& scene, const EyeCamera& camera, const Ray& ray,
                                           const Hit& first, const StereoReuseView& reuse, PixelSample& pixel,
                                           SurfaceRecord* surfaceOut = nullptr) {
  pixel.firstPrim = first.primId;
  pixel.inverseDepth = firstHitInverseDepth(camera, ray, first);
  if (surfaceOut) *surfaceOut = surfaceRecordOf(scene, camera, ray, first);
  if (reuse.mode == StereoMode::Gather) pixel.reusedFrom = gatherSource(reuse, surfaceRecordOf(scene, camera, ray, first));
}

// A reused pixel's gather point: the other eye's finished colour at its source pixel, no estimate.
PVR_HOST_DEVICE inline GatherPoint reusedGatherPoint(const StereoReuseView& reuse, uint32_t source) {
  GatherPoint reused;
  reused.radiance = reuse.sourceImage[source];
  return reused;
}

// Sample s of pixel (x, y), traced up to its gather point. Sample 0 (the pixel centre) fills in
// `pixel` (the first hit, and whether the pixel reuses the other eye's shading
// (`reuse`)) and writes the pixel's surface record to `surfaceOut` if given (the left eye under
// reuse: written at once, so that it is not kept live through the density estimate); later
// samples read the decision from `pixel`. A reused pixel's gather point carries
// the other eye's finished colour and needs no estimate. The random numbers of a pixel that is
// not reused are those of separate rendering, so it comes out bit for bit the same.
template <class Intersector>
PVR_HOST_DEVICE GatherPoint pixelGatherPoint(const SceneView& scene, const Intersector& intersector,
                                             const GatherParams& params, const EyeCamera& camera, Eye eye, int x,
                                             int y, int s, const StereoReuseView& reuse, PixelSample& pixel,
                                             SurfaceRecord* surfaceOut = nullptr) {
  if (s == 0 && reuse.mode == StereoMode::Scatter) {
    pixel.reusedFrom = scatteredSource(reuse.scattered[size_t(y) * camera.width + x]);
    if (pixel.reusedFrom != kNotReused) {
      const SurfaceRecord& source = reuse.sourceSurfaces[pixel.reusedFrom];
      pixel.firstPrim = source.prim;
      pixel.inverseDepth = camera.inverseDepthOf(source.position);
    }
  }
  if (pixel.reusedFrom != kNotReused) return reusedGatherPoint(reuse, pixel.reusedFrom);
  CounterRng rng(0, 0, 0);
  Ray ray = pixelSampleRay(params, camera, eye, x, y, s, rng);
  if (s > 0) return traceToGatherPoint(scene, intersector, params, ray, rng, nullptr, camera.pixelSpread());
  const Hit first = sampleZeroFirstHit(scene, intersector, params, x, y, ray);
  recordFirstHit(scene, camera, ray, first, reuse, pixel, surfaceOut);
  if (pixel.reusedFrom != kNotReused) return reusedGatherPoint(reuse, pixel.reusedFrom);
  return traceToGatherPoint(scene, intersector, params, ray, rng, &first, camera.pixelSpread());
}

// A foveation mask vertex at image position (px, py). On a pixel centre (all of the mask's
// full-density part) it is that pixel's first sample, with the same random numbers, stereo reuse
// (`reuse`), and its surface record written to `surfaces` (per pixel: the eye another one reuses)
// if given. Elsewhere it is shaded on its own. `sample` receives the first hit's inverse depth and
// the reuse decision.
template <class Intersector>
PVR_HOST_DEVICE GatherPoint vertexGatherPoint(const SceneView& scene, const Intersector& intersector,
                                              const GatherParams& params, const EyeCamera& camera, Eye eye, float px,
                                              float py, const StereoReuseView& reuse, PixelSample& sample,
                                              SurfaceRecord* surfaces = nullptr) {
  const float fx = floorf(px), fy = floorf(py);
  if (px - fx == 0.5f && py - fy == 0.5f && camera.containsPixel(px, py)) {
    const int x = int(fx), y = int(fy);
    return pixelGatherPoint(scene, intersector, params, camera, eye, x, y, 0, reuse, sample,
                            surfaces ? surfaces + size_t(y) * camera.width + x : nullptr);
  }
  return imagePositionGatherPoint(scene, intersector, params, camera, eye, px, py, sample.inverseDepth);
}

// Pixel (x, y) of one eye: the average of samplesPerPixel jittered rays, or the other eye's
// colour where `reuse` finds the same surface point. `guideOut`, if given, receives what the
// denoiser needs (a reused pixel's direct part is its whole colour: the denoiser takes the other
// eye's guides there).
template <class Intersector, class PhotonMap>
PVR_HOST_DEVICE PixelSample shadePixel(const SceneView& scene, const Intersector& intersector, const PhotonMap& map,
                                       const GatherParams& params, const EyeCamera& camera, Eye eye, int x, int y,
                                       const StereoReuseView& reuse = StereoReuseView(),
                                       SurfaceRecord* surfaceOut = nullptr, PixelGuide* guideOut = nullptr) {
  PixelSample out;
  PixelGuide guide;
  for (int s = 0; s < params.samplesPerPixel; ++s) {
    GatherPoint point = pixelGatherPoint(scene, intersector, params, camera, eye, x, y, s, reuse, out,
                                         s == 0 ? surfaceOut : nullptr);
    if (out.reusedFrom != kNotReused) {  // the other eye's finished colour
      out.radiance = point.radiance;
      if (guideOut) guideOut->direct = point.radiance, guideOut->emitted = Vec3(0.0f);
      return out;
    }
    if (guideOut) {
      guide.direct += point.radiance;
      guide.emitted += point.emitted;
      if (s == 0) guide.albedo = point.reflectance, guide.normal = point.normal;
    }
    out.radiance += finishGather(map, point, params.density);
  }
  out.radiance *= 1.0f / float(params.samplesPerPixel);
  if (guideOut) {
    guide.direct *= 1.0f / float(params.samplesPerPixel);
    guide.emitted *= 1.0f / float(params.samplesPerPixel);
    *guideOut = guide;
  }
  return out;
}

}  // namespace pvr
