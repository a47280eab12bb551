#pragma once
// The second pass of photon mapping: the radiance arriving at the eye along one pixel's ray,
// written once for any Intersector (`intersect`, `occluded`) and any photon map.
//
// The ray follows mirrors and glass (a specular chain) to the first diffuse surface. There:
//  - ShadingMode::Full: emission + direct light by one shadow ray to a light sample + caustic and
//    indirect light from the photon map (which then holds no direct, L D, photons);
//  - ShadingMode::PhotonMapOnly: emission + everything else from the photon map (the main paper's
//    formulation; the map then holds every photon including the direct ones).
#include "pvr/camera/stereo_rig.h"
#include "pvr/photon/density.h"
#include "pvr/shading/scene_view.h"
#include "pvr/util/rng.h"

namespace pvr {

enum class ShadingMode : int { Full = 0, PhotonMapOnly = 1 };

struct GatherParams {
  DensityParams density;
  ShadingMode mode = ShadingMode::Full;
  int maxSpecularDepth = 8;  ///< mirror/glass bounces followed from the eye
  int samplesPerPixel = 1;
  uint32_t seed = 1;
};

struct PixelSample {
  Vec3 radiance{0, 0, 0};
  uint32_t firstPrim = ~0u;  ///< triangle seen first by the pixel's centre sample, ~0u for none
};

// Where an eye path meets its first diffuse surface, with everything gathered on the way except
// the photon-map estimate there: radiance = emitted + direct light, and the estimate still to add
// is weight * estimateFluxDensity(position, normal). Splitting here is what lets the GPU trace eye
// rays in one kernel and estimate densities in another (the paper's hybrid scheme).
struct GatherPoint {
  Vec3 radiance{0, 0, 0};
  Vec3 weight{0, 0, 0};  ///< throughput * albedo / pi; zero when the path found no diffuse surface
  Vec3 position{0, 0, 0};
  Vec3 normal{0, 0, 0};  ///< geometric normal facing the arriving ray
  PVR_HOST_DEVICE bool needsEstimate() const { return !isBlack(weight); }
};

// Follows the eye ray through mirrors and glass to the first diffuse surface.
template <class Intersector>
PVR_HOST_DEVICE GatherPoint traceToDiffuse(const SceneView& scene, const Intersector& intersector,
                                           const GatherParams& params, Ray ray, CounterRng& rng, uint32_t* firstPrim) {
  GatherPoint out;
  Vec3 throughput{1, 1, 1};
  float eps = scene.rayEpsilon();
  for (int depth = 0; depth <= params.maxSpecularDepth; ++depth) {
    Hit hit;
    if (!intersector.intersect(ray, INFINITY, hit)) break;
    if (depth == 0 && firstPrim) *firstPrim = hit.primId;
    SurfacePoint sp = scene.surfacePoint(hit);
    const Material& m = scene.materials[sp.materialId];
    bool front = dot(ray.dir, sp.geometricNormal) < 0.0f;
    if (front && m.isEmissive()) out.radiance += throughput * m.emission;
    if (m.type == MaterialType::Diffuse) {
      Vec3 nGeo = front ? sp.geometricNormal : -sp.geometricNormal;
      Vec3 nShade = front ? sp.shadingNormal : -sp.shadingNormal;
      Vec3 brdf = m.albedo * kInvPi;
      if (params.mode == ShadingMode::Full && scene.lightCount > 0) {
        float uPick = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
        LightSample ls = sampleLight(scene, uPick, u1, u2);
        Vec3 toLight = ls.position - sp.position;
        float dist2 = lengthSquared(toLight);
        float dist = sqrtf(dist2);
        Vec3 wi = toLight / dist;
        float cosSurface = dot(nShade, wi), cosLight = -dot(ls.normal, wi);
        if (cosSurface > 0.0f && cosLight > 0.0f && dot(nGeo, wi) > 0.0f) {
          Ray shadow{sp.position + nGeo * eps, wi};
          if (!intersector.occluded(shadow, dist * (1.0f - 1e-3f) - eps))
            out.radiance += throughput * brdf * ls.emission * (cosSurface * cosLight / (dist2 * ls.pdfArea));
        }
      }
      out.weight = throughput * brdf;
      out.position = sp.position;
      out.normal = nGeo;
      break;
    }
    ray.dir = scatterSpecular(m, ray.dir, sp.shadingNormal, rng.uniform(), throughput);
    Vec3 side = dot(ray.dir, sp.geometricNormal) > 0.0f ? sp.geometricNormal : -sp.geometricNormal;
    ray.origin = sp.position + side * eps;
  }
  return out;
}

// Adds the photon-map estimate at the gather point.
template <class PhotonMap>
PVR_HOST_DEVICE Vec3 finishGather(const PhotonMap& map, const GatherPoint& point, const DensityParams& density) {
  if (!point.needsEstimate()) return point.radiance;
  return point.radiance + point.weight * estimateFluxDensity(map, point.position, point.normal, density);
}

template <class Intersector, class PhotonMap>
PVR_HOST_DEVICE Vec3 radianceAlongRay(const SceneView& scene, const Intersector& intersector, const PhotonMap& map,
                                      const GatherParams& params, Ray ray, CounterRng& rng, uint32_t* firstPrim) {
  return finishGather(map, traceToDiffuse(scene, intersector, params, ray, rng, firstPrim), params.density);
}

// The camera ray of sample s of pixel (x, y), with the random numbers that continue its path. The
// first sample goes through the pixel centre, so the first-hit id is stable.
PVR_HOST_DEVICE inline Ray pixelSampleRay(const GatherParams& params, const EyeCamera& camera, Eye eye, int x, int y,
                                          int s, CounterRng& rng) {
  uint32_t pixelIndex = uint32_t(y) * uint32_t(camera.width) + uint32_t(x);
  uint32_t eyeSeed = hashCombine(params.seed, 0x51ed270bu + uint32_t(eye));
  rng = CounterRng(eyeSeed, pixelIndex, uint32_t(s));
  float jx = s == 0 ? 0.5f : rng.uniform(), jy = s == 0 ? 0.5f : rng.uniform();
  return camera.generateRay(float(x) + jx, float(y) + jy);
}

// Radiance of pixel (x, y) of one eye: the average of samplesPerPixel jittered rays.
template <class Intersector, class PhotonMap>
PVR_HOST_DEVICE PixelSample shadePixel(const SceneView& scene, const Intersector& intersector, const PhotonMap& map,
                                       const GatherParams& params, const EyeCamera& camera, Eye eye, int x, int y) {
  PixelSample out;
  for (int s = 0; s < params.samplesPerPixel; ++s) {
    CounterRng rng(0, 0, 0);
    Ray ray = pixelSampleRay(params, camera, eye, x, y, s, rng);
    out.radiance += radianceAlongRay(scene, intersector, map, params, ray, rng, s == 0 ? &out.firstPrim : nullptr);
  }
  out.radiance *= 1.0f / float(params.samplesPerPixel);
  return out;
}

}  // namespace pvr
