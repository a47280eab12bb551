#pragma once
// Photon tracing from the area lights (the first pass of photon mapping), written once for any
// Intersector with `bool intersect(const Ray&, float tMax, Hit&) const`.
//
// Emission: a light chosen in proportion to its power. From a triangle: a uniform point on it, a
// cosine-weighted direction; the photon carries Le * pi * area / (pdf_pick * N), which is exactly
// Phi / N when all lights share one colour. A point light: a uniform direction, 4 pi I / (pick N);
// a spot: uniform within the outer cone, weighted by its falloff; a distant light: a uniform point
// on a disk as wide as the scene's bounding sphere, upstream of it, carrying E pi R^2 / (pick N);
// the sky: a uniform direction of the upper hemisphere through such a disk, L 2 pi^2 R^2 / (pick N).
// At a diffuse surface the photon is stored, then
// continues with Russian roulette (probability = max albedo component, power scaled so the
// expectation is unchanged). A microfacet surface stores the photon too, then samples its whole
// BSDF (shading/bsdf.h), with Russian roulette on the sample's weight. Mirrors reflect and glass
// reflects or refracts (by Fresnel); photons are never stored on them.
#include "pvr/camera/stereo_rig.h"
#include "pvr/photon/photon.h"
#include "pvr/shading/scene_view.h"
#include "pvr/util/rng.h"

namespace pvr {

struct PhotonTraceParams {
  uint32_t photonCount = 256 * 256;  ///< emitted photons N (each carries 1/N of the power)
  // The photons traced: indices [firstPhoton, firstPhoton + tracedPhotons) of the N (0: up to N).
  // A rolling photon map traces a slice of them per frame.
  uint32_t firstPhoton = 0;
  uint32_t tracedPhotons = 0;
  uint32_t seed = 1;
  int maxDepth = 8;  ///< surface interactions per photon path
  bool storeDirect = false;  ///< also store L D photons (when the photon map alone shades)
  PVR_HOST_DEVICE uint32_t lastPhoton() const {  ///< one past the last index traced
    const uint32_t end = tracedPhotons ? firstPhoton + tracedPhotons : photonCount;
    return end < photonCount ? end : photonCount;
  }
};

// A uniform point on a disk of `radius` around `center` facing `frameNormal`, moved upstream
// (against `travel`) past the whole scene: where a distant light's or the sky's photon starts.
PVR_HOST_DEVICE inline Vec3 upstreamDiskPoint(const SceneView& scene, Vec3 center, float radius, Vec3 frameNormal,
                                              Vec3 travel, float u1, float u2) {
  Frame frame = Frame::fromNormal(frameNormal);
  float r = radius * sqrtf(u1), phi = 2.0f * kPi * u2;
  float back = length(center - scene.sceneCenter) + 2.0f * scene.sceneRadius;
  return center - travel * back + frame.toWorld({r * cosf(phi), r * sinf(phi), 0.0f});
}

// The emitted photon i: origin, direction and power.
PVR_HOST_DEVICE inline Photon emitPhoton(const SceneView& scene, const PhotonTraceParams& params, uint32_t i) {
  CounterRng rng(params.seed, i, 0);
  float uPick = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
  LightSample ls = sampleLight(scene, uPick, u1, u2);
  // Two statements: the order of evaluation of arguments differs between g++ and nvcc.
  float uTheta = rng.uniform();
  float uPhi = rng.uniform();
  Photon p;
  if (ls.sky) {  // a uniform direction from the upper hemisphere through a disk facing it
    const float n = float(params.photonCount) * ls.pick;
    const float sinTheta = sqrtf(fmaxf(0.0f, 1.0f - uTheta * uTheta));
    Vec3 toSky = Frame::fromNormal({0, 1, 0}).toWorld(
        {sinTheta * cosf(2.0f * kPi * uPhi), sinTheta * sinf(2.0f * kPi * uPhi), uTheta});
    const SkyLight& sky = scene.sky;
    const float radius = sky.photonRadius(scene.sceneRadius);
    const Vec3 center = sky.aimRadius > 0.0f ? sky.aimCenter : scene.sceneCenter;
    p.position = upstreamDiskPoint(scene, center, radius, toSky, -toSky, u1, u2);
    p.direction = -toSky;
    p.power = sky.radiance * (2.0f * kPi * kPi * radius * radius / n);
    return p;
  }
  if (ls.punctual >= 0) {
    const PunctualLight& l = scene.punctualLights[ls.punctual];
    const float n = float(params.photonCount) * ls.pick;
    if (l.kind == PunctualKind::Directional) {
      const bool aimed = l.aimRadius > 0.0f;
      const float radius = aimed ? l.aimRadius : scene.sceneRadius;
      const Vec3 center = aimed ? l.position : scene.sceneCenter;
      p.position = upstreamDiskPoint(scene, center, radius, l.direction, l.direction, u1, u2);
      p.direction = l.direction;
      p.power = l.intensity * (kPi * radius * radius / n);
      return p;
    }
    float cosMin = l.kind == PunctualKind::Spot ? l.cosOuter : -1.0f;  // uniform in the cone (the sphere: -1)
    float cosTheta = 1.0f - uTheta * (1.0f - cosMin), sinTheta = sqrtf(fmaxf(0.0f, 1.0f - cosTheta * cosTheta));
    float phi = 2.0f * kPi * uPhi;
    p.position = l.position;
    p.direction = Frame::fromNormal(l.direction).toWorld({sinTheta * cosf(phi), sinTheta * sinf(phi), cosTheta});
    p.power = l.intensity * (l.falloff(cosTheta) * 2.0f * kPi * (1.0f - cosMin) / n);
    return p;
  }
  Vec3 local = sampleCosineHemisphere(uTheta, uPhi);
  p.position = ls.position;
  p.direction = Frame::fromNormal(ls.normal).toWorld(local);
  p.power = ls.emission * (kPi / (ls.pdfArea * float(params.photonCount)));
  return p;
}

// A photon's path between surface interactions: what the next interaction needs. The GPU tracer
// keeps one per lane and starts a new photon as soon as a lane's path ends, so that a warp's lanes
// do not wait for its longest path.
struct PhotonPath {
  Ray ray;
  Vec3 power;
  Vec3 offsetNormal;  ///< the side the ray leaves its surface on
  uint32_t index = 0;  ///< the emitted photon's index: its random numbers
  int depth = 0;       ///< surface interactions so far
  int stored = 0;      ///< photons written to its output so far
};

PVR_HOST_DEVICE inline PhotonPath startPhotonPath(const SceneView& scene, const PhotonTraceParams& params, uint32_t i) {
  const Photon photon = emitPhoton(scene, params, i);
  PhotonPath path;
  path.ray = Ray{photon.position, photon.direction};
  path.power = photon.power;
  path.offsetNormal = photon.direction;  // leave the light along its emission side
  path.index = i;
  return path;
}

// The path's next surface interaction: traces its ray, stores a photon at out[path.stored] where
// one is due, and scatters. False when the path ends (it left the scene, was absorbed, or reached
// params.maxDepth interactions).
template <class Intersector>
PVR_HOST_DEVICE bool advancePhotonPath(const SceneView& scene, const Intersector& intersector,
                                       const PhotonTraceParams& params, PhotonPath& path, Photon* out) {
  if (path.depth >= params.maxDepth) return false;
  const int depth = path.depth++;
  Ray& ray = path.ray;
  ray.origin = ray.origin + path.offsetNormal * scene.rayEpsilon();
  Hit hit;
  if (!intersector.intersect(ray, INFINITY, hit)) return false;
  SurfacePoint sp = scene.surfacePoint(hit);
  const Material& m = scene.materials[sp.materialId];
  CounterRng rng(params.seed, path.index, uint32_t(depth) + 1);
  Vec3 dir = ray.dir;
  if (m.type == MaterialType::Microfacet) {
    if (depth > 0 || params.storeDirect) {
      Photon& s = out[path.stored++];
      s.position = sp.position;
      s.power = path.power;
      s.direction = dir;
    }
    // Three statements: the order of evaluation of arguments differs between g++ and nvcc.
    float uLobe = rng.uniform();
    float u1 = rng.uniform();
    float u2 = rng.uniform();
    BsdfSample bs = sampleBsdf(scene.bsdfAt(m, hit, sp, -dir), -dir, uLobe, u1, u2);
    if (!bs.valid()) return false;
    float survive = fminf(1.0f, maxComponent(bs.weight));
    if (!(rng.uniform() < survive)) return false;
    path.power *= bs.weight * (1.0f / survive);
    ray.dir = bs.wi;
    path.offsetNormal = dot(ray.dir, sp.geometricNormal) > 0.0f ? sp.geometricNormal : -sp.geometricNormal;
  } else if (m.type == MaterialType::Diffuse) {
    Vec3 nFacing = dot(dir, sp.geometricNormal) < 0.0f ? sp.geometricNormal : -sp.geometricNormal;
    Vec3 nShade = dot(sp.shadingNormal, nFacing) < 0.0f ? -sp.shadingNormal : sp.shadingNormal;
    bool direct = depth == 0;  // L D: shaded by shadow rays unless the map shades alone
    if (!direct || params.storeDirect) {
      Photon& s = out[path.stored++];
      s.position = sp.position;
      s.power = path.power;
      s.direction = dir;
    }
    Vec3 albedo = scene.albedoAt(m, hit.primId, hit.u, hit.v);
    float survive = fminf(1.0f, maxComponent(albedo));
    if (!(rng.uniform() < survive)) return false;
    path.power *= albedo * (1.0f / survive);
    // Two statements: the order of evaluation of arguments differs between g++ and nvcc.
    float uTheta = rng.uniform();
    float uPhi = rng.uniform();
    Vec3 local = sampleCosineHemisphere(uTheta, uPhi);
    ray.dir = Frame::fromNormal(nShade).toWorld(local);
    if (dot(ray.dir, nFacing) <= 0.0f) return false;  // shading normal sent it below the surface
    path.offsetNormal = nFacing;
  } else {
    Vec3 throughput{1, 1, 1};
    ray.dir = scatterSpecular(m, dir, sp.shadingNormal, rng.uniform(), throughput);
    path.power *= throughput;
    path.offsetNormal = dot(ray.dir, sp.geometricNormal) > 0.0f ? sp.geometricNormal : -sp.geometricNormal;
  }
  ray.origin = sp.position;
  return true;
}

// Traces photon i; writes at most params.maxDepth photons to `out` and returns how many.
template <class Intersector>
PVR_HOST_DEVICE int tracePhoton(const SceneView& scene, const Intersector& intersector,
                                const PhotonTraceParams& params, uint32_t i, Photon* out) {
  PhotonPath path = startPhotonPath(scene, params, i);
  while (advancePhotonPath(scene, intersector, params, path, out)) {
  }
  return path.stored;
}

}  // namespace pvr
