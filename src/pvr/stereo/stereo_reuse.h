#pragma once
// Binocular reuse (the main paper's section 3.3): the right eye takes the left eye's shading
// where both eyes see the same point of a diffuse surface.
//
// Only view-independent shading is reused. A Lambertian surface sends the same radiance towards
// both eyes (its emission, direct light and photon-map estimate), so a pixel whose centre ray
// reaches a diffuse surface directly may take the other eye's value for that point. A pixel that
// sees a mirror or glass shows a different point of the scene to each eye, and any glossy term
// would change with the eye's direction: those pixels are always shaded per eye. (The paper
// reuses every hit point and is wrong for such surfaces.)
//
// Two schemes, both deciding per pixel from its centre ray:
//  - Scatter (the paper's): every reusable left hit point that the right eye can see (a
//    visibility ray to the right eye) is projected into the right image; where several land on
//    one right pixel the nearest wins (distance and left pixel index in one 64-bit atomic
//    minimum). Right pixels that received nothing are shaded.
//  - Gather (ours): every right pixel traces its primary ray; its hit point, projected into the
//    left image, reuses that left pixel if the left pixel's own hit is the same surface point:
//    the same triangle, or a neighbouring one of the same material and orientation (a
//    tessellated surface: with triangles of a pixel or less, the same-triangle test alone would
//    reuse little), seen from the same side, within the pixel's footprint along the surface and
//    a tenth of it off the surface. No holes, no visibility rays.
#include "pvr/camera/stereo_rig.h"
#include "pvr/shading/scene_view.h"

namespace pvr {

enum class StereoMode : int { Separate = 0, Scatter = 1, Gather = 2 };

inline const char* stereoModeName(StereoMode m) {  ///< "separate" | "scatter" | "gather"
  return m == StereoMode::Scatter ? "scatter" : m == StereoMode::Gather ? "gather" : "separate";
}

constexpr uint32_t kNotReused = ~0u;            ///< a pixel shaded by its own eye
constexpr uint64_t kNothingScattered = ~0ull;  ///< scatter buffer entry no left point reached
constexpr float kSameSurfaceCosine = 0.95f;     ///< normals closer than ~18 degrees agree

// The first hit of a pixel's centre ray when it is a Lambertian surface reached directly (no
// mirror or glass before it; microfacet surfaces are view-dependent): what the other eye may reuse. prim == ~0u when there is none.
struct SurfaceRecord {
  Vec3 position{0, 0, 0};
  uint32_t prim = ~0u;
  Vec3 normal{0, 0, 0};  ///< geometric normal, facing the eye
  float footprint = 0;   ///< size of the pixel on the surface at this point: the same-point tolerance
  uint32_t material = 0;
  PVR_HOST_DEVICE bool reusable() const { return prim != ~0u; }
};

// Size of one pixel of `camera` on a surface at `position` with unit normal `normal` facing it:
// the pixel's width in the plane of constant depth, stretched by the surface's slant (limited,
// so that grazing surfaces keep a finite tolerance).
PVR_HOST_DEVICE inline float pixelFootprint(const EyeCamera& camera, Vec3 position, Vec3 normal) {
  Vec3 toPoint = position - camera.pose.position;
  float distance = length(toPoint);
  float depth = -camera.pose.toLocalPoint(position).z;
  float pixelX = (tanf(camera.fov.angleRight) - tanf(camera.fov.angleLeft)) / float(camera.width);
  float pixelY = (tanf(camera.fov.angleUp) - tanf(camera.fov.angleDown)) / float(camera.height);
  float cosine = distance > 0.0f ? fabsf(dot(normal, toPoint)) / distance : 1.0f;
  return depth * fmaxf(pixelX, pixelY) / fmaxf(cosine, 0.2f);
}

// The record of a centre ray's first hit (`hit` may be a miss).
PVR_HOST_DEVICE inline SurfaceRecord surfaceRecordOf(const SceneView& scene, const EyeCamera& camera, const Ray& ray,
                                                     const Hit& hit) {
  SurfaceRecord record;
  if (!hit.valid() || !scene.material(hit.primId).isViewIndependent()) return record;
  SurfacePoint sp = scene.surfacePoint(hit);
  record.position = sp.position;
  record.normal = dot(ray.dir, sp.geometricNormal) < 0.0f ? sp.geometricNormal : -sp.geometricNormal;
  record.footprint = pixelFootprint(camera, sp.position, record.normal);
  record.prim = hit.primId;
  record.material = scene.materialIds[hit.primId];
  return record;
}

// What a reusing eye reads from the eye it reuses.
struct StereoReuseView {
  StereoMode mode = StereoMode::Separate;
  EyeCamera source;                               ///< the eye whose shading is reused (the left)
  const SurfaceRecord* sourceSurfaces = nullptr;  ///< per source pixel
  const Vec3* sourceImage = nullptr;              ///< the source eye's finished image
  const uint64_t* scattered = nullptr;            ///< Scatter: per pixel of this eye, packScatter() or kNothingScattered

  PVR_HOST_DEVICE bool reusing() const { return mode != StereoMode::Separate; }
};

// Scatter's buffer entry: the distance to the target eye in the high word (a non-negative float's
// bits order like the float), so the atomic minimum keeps the nearest point; the left pixel in
// the low word, so the colour is read losslessly from the left image.
PVR_HOST_DEVICE inline uint64_t packScatter(float distance, uint32_t sourcePixel) {
  return (uint64_t(floatBits(distance)) << 32) | sourcePixel;
}
PVR_HOST_DEVICE inline uint32_t scatteredSource(uint64_t entry) {
  return entry == kNothingScattered ? kNotReused : uint32_t(entry & 0xffffffffu);
}

// Scatter, for one left pixel's record: the right pixel it lands on and its buffer entry, if the
// point faces the right eye, projects inside the right image and nothing hides it from the eye.
template <class Intersector>
PVR_HOST_DEVICE bool scatterTarget(const SceneView& scene, const Intersector& intersector, const SurfaceRecord& record,
                                   uint32_t sourcePixel, const EyeCamera& target, uint32_t& targetPixel,
                                   uint64_t& entry) {
  if (!record.reusable()) return false;
  Vec3 toEye = target.pose.position - record.position;
  float distance = length(toEye);
  if (!(distance > 0.0f)) return false;
  Vec3 dir = toEye / distance;
  if (dot(dir, record.normal) <= 0.0f) return false;  // the target eye sees its back
  float px, py;
  if (!target.project(record.position, px, py) || !target.containsPixel(px, py)) return false;
  float eps = scene.rayEpsilon();
  if (intersector.occluded(Ray{record.position + record.normal * eps, dir}, distance * (1.0f - 1e-3f) - eps))
    return false;
  targetPixel = uint32_t(py) * uint32_t(target.width) + uint32_t(px);
  entry = packScatter(distance, sourcePixel);
  return true;
}

// Gather, for one right pixel's record: the left pixel whose shading it may take, or kNotReused.
PVR_HOST_DEVICE inline uint32_t gatherSource(const StereoReuseView& reuse, const SurfaceRecord& here) {
  if (!here.reusable()) return kNotReused;
  const EyeCamera& source = reuse.source;
  float px, py;
  if (!source.project(here.position, px, py) || !source.containsPixel(px, py)) return kNotReused;
  uint32_t pixel = uint32_t(py) * uint32_t(source.width) + uint32_t(px);
  const SurfaceRecord& there = reuse.sourceSurfaces[pixel];
  // The same triangle, or another of the same material: position and orientation decide.
  if (!there.reusable() || there.material != here.material || dot(there.normal, here.normal) < kSameSurfaceCosine)
    return kNotReused;
  float tolerance = fmaxf(there.footprint, here.footprint);
  Vec3 offset = there.position - here.position;
  if (lengthSquared(offset) > tolerance * tolerance || fabsf(dot(offset, here.normal)) > 0.1f * tolerance)
    return kNotReused;
  return pixel;
}

}  // namespace pvr
