#pragma once
// Sample 0's first hits of one eye, found before the eye pass: either as a rasterised visibility
// buffer gives them (gbuffer_raster.h, Ray-VR's G-buffer pre-pass: per pixel the triangle seen at
// the pixel centre and its barycentrics), or traced by a camera-ray kernel of their own (the GPU's
// first-hit pre-pass: a lean kernel traces at the standalone ray rate, where the eye kernel's
// registers held the same rays to a third of it). The eye pass starts from them instead of
// tracing its primary rays. Written once for both backends (host and device pointers alike).
#include <cstddef>
#include <cstdint>

#include "pvr/geometry/ray.h"
#include "pvr/math/vec.h"
#include "pvr/shading/scene_view.h"

namespace pvr {

struct PrimaryHitsView {
  const uint32_t* prim = nullptr;      ///< per pixel, row-major: the triangle, ~0u for none (the sky)
  const Vec2* barycentrics = nullptr;  ///< per pixel: of the triangle's vertices 1 and 2 (Hit::u, Hit::v)
  // Or, per pixel, the hit of sample 0's own ray (jittered or not) as the intersector reported it:
  // taken as it is, so the pass's result is bit for bit that of tracing it in place.
  const Hit* traced = nullptr;
  int width = 0;
  PVR_HOST_DEVICE bool present() const { return prim != nullptr; }
};

// Pixel (x, y)'s first hit along its centre ray `ray`, from the buffer: exactly the hit a traced
// ray reports but for the barycentrics' rounding (the distance is the ray's to that point).
// Returns false where the ray has to be traced after all: the triangle cuts texels out (the
// rasteriser tests no alpha), or an id or distance the scene cannot have.
PVR_HOST_DEVICE inline bool rasterisedFirstHit(const SceneView& scene, const PrimaryHitsView& hits, int x, int y,
                                               const Ray& ray, Hit& hit) {
  const size_t pixel = size_t(y) * size_t(hits.width) + size_t(x);
  const uint32_t prim = hits.prim[pixel];
  hit = Hit();
  if (prim == ~0u) return true;
  if (prim >= scene.triangleCount || scene.materials[scene.materialIds[prim]].alphaTested()) return false;
  const Vec2 b = hits.barycentrics[pixel];
  const float u = fminf(fmaxf(b.x, 0.0f), 1.0f);
  const float v = fminf(fmaxf(b.y, 0.0f), 1.0f - u);
  Vec3 p0, p1, p2;
  scene.triangle(prim, p0, p1, p2);
  const float t = dot(p0 * (1.0f - u - v) + p1 * u + p2 * v - ray.origin, ray.dir);
  if (!(t > 0.0f)) return false;
  hit.t = t, hit.primId = prim, hit.u = u, hit.v = v;
  return true;
}

}  // namespace pvr
