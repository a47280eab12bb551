#pragma once
// Shadow rays traced in a kernel of their own (a wavefront), the shading code unchanged. The GPU's
// eye pass runs the shared gathering code twice per pixel: first through RecordedShadows, which
// writes down the shadow queries it is asked (the first kMaxDeferredShadows) and answers each
// "visible"; then a lean kernel traces the recorded queries at the standalone shadow-ray rate; then
// the gathering code again through ReplayedShadows, which answers the queries, in the order they
// are asked, from that kernel's results (and traces any beyond kMaxDeferredShadows in place).
//
// Why the answers match: nothing in the gathering code decides on a shadow ray's answer but how
// much light it adds. Its random numbers, the paths it follows and the next queries it asks are the
// same whatever the answers, so the second run asks the first run's queries in the same order, and
// the pixel comes out bit for bit as if traced in place. The first run's shading is thrown away, so
// a compiler keeps of it only what the queries depend on.
#include <cstddef>
#include <cstdint>

#include "pvr/geometry/ray.h"
#include "pvr/math/vec.h"

namespace pvr {

// Shadow queries recorded per pixel and sample; a gather point asks about 1-4 (sun, one chosen
// point light, sky, area light), more only with a ray to every light among many.
constexpr int kMaxDeferredShadows = 4;

// One recorded shadow ray: blocked if anything lies along it closer than tMax.
struct alignas(16) ShadowQuery {
  Vec3 origin;
  float tMax = 0.0f;
  Vec3 dir;
  float unused = 0.0f;
};

// A pass's queries: query k of pixel i at [k * pixels + i], so that the shadow kernel's warps,
// over neighbouring pixels' k-th queries (mostly towards the same light), trace alike rays.
struct DeferredShadowsView {
  ShadowQuery* queries = nullptr;  ///< kMaxDeferredShadows planes of `pixels`
  uint8_t* asked = nullptr;        ///< per pixel: the queries recorded (at most kMaxDeferredShadows)
  uint8_t* blocked = nullptr;      ///< like `queries`: the answers (1: blocked)
  size_t pixels = 0;
};

// The first run's intersector: closest hits from `inner`, shadow queries recorded and answered
// "visible". `queries` points at the pixel's first plane entry.
template <class Inner>
struct RecordedShadows {
  Inner inner;
  ShadowQuery* queries = nullptr;
  size_t stride = 0;
  mutable int asked = 0;
  PVR_HOST_DEVICE bool intersect(const Ray& ray, float tMax, Hit& hit) const { return inner.intersect(ray, tMax, hit); }
  PVR_HOST_DEVICE bool occluded(const Ray& ray, float tMax) const {
    if (asked < kMaxDeferredShadows) {
      ShadowQuery q;
      q.origin = ray.origin, q.dir = ray.dir, q.tMax = tMax;
      queries[size_t(asked) * stride] = q;
    }
    ++asked;
    return false;  // the first run's light is thrown away: any answer will do
  }
  PVR_HOST_DEVICE int recorded() const { return asked < kMaxDeferredShadows ? asked : kMaxDeferredShadows; }
};

// The second run's intersector: the recorded queries answered from `blocked` (the pixel's first
// plane entry), in the order asked; later ones traced by `inner`.
template <class Inner>
struct ReplayedShadows {
  Inner inner;
  const uint8_t* blocked = nullptr;
  size_t stride = 0;
  mutable int asked = 0;
  PVR_HOST_DEVICE bool intersect(const Ray& ray, float tMax, Hit& hit) const { return inner.intersect(ray, tMax, hit); }
  PVR_HOST_DEVICE bool occluded(const Ray& ray, float tMax) const {
    const int k = asked++;
    if (k < kMaxDeferredShadows) return blocked[size_t(k) * stride] != 0;
    return inner.occluded(ray, tMax);
  }
};

// The shadow kernel's work for query k of pixel i (host and device alike).
template <class Intersector>
PVR_HOST_DEVICE inline void answerShadowQuery(const Intersector& intersector, const DeferredShadowsView& v, int k,
                                              size_t i) {
  if (k >= int(v.asked[i])) return;
  const size_t at = size_t(k) * v.pixels + i;
  const ShadowQuery q = v.queries[at];
  v.blocked[at] = intersector.occluded(Ray{q.origin, q.dir}, q.tMax) ? 1 : 0;
}

}  // namespace pvr
