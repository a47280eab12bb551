#pragma once
// Density estimation, the main paper's equation 1:
//   L_r(x, w) ~ 1 / (pi r^2) * sum_p f_r(x, w_p, w) * dPhi_p
// either over all photons within a fixed radius (no heap: the paper's choice) or over the k
// nearest within a maximum radius, with r the k-th distance (max-heap, radius shrinking).
// Works on any photon map with `search(q, r2, visitor)`: HashGridView, KdTreeView.
#include <cmath>

#include "pvr/photon/knn_heap.h"
#include "pvr/photon/photon.h"

namespace pvr {

enum class Estimator : int { Radius = 0, Knn = 1 };

// What the estimate's support is where a surface meets another (photon/boundary.h).
enum class Boundary : int {
  Sphere = 0,  ///< the paper's: photons within r in 3D, divided by pi r^2
  Clipped = 1, ///< photons beyond the nearest wall left out, divided by the disc's area on the surface (walls, edges)
};

struct DensityParams {
  float radius = 0.05f;  ///< search radius (the maximum radius for kNN)
  Estimator estimator = Estimator::Radius;
  int k = 32;  ///< photons for kNN, 1..kMaxKnn
  Boundary boundary = Boundary::Sphere;
};

// Knaus and Zwicker's (2011) progressive radius of pass `pass` (from 0): r_{i+1}^2 = r_i^2 (i + alpha)
// / (i + 1) from r_0 = first, so r_n^2 = first^2 Gamma(n + 1 + alpha) / (Gamma(1 + alpha) Gamma(n + 2)).
inline float progressiveRadius(float first, int pass, float alpha) {
  const double n = double(pass);
  const double r2 = std::exp(std::lgamma(n + 1.0 + alpha) - std::lgamma(1.0 + alpha) - std::lgamma(n + 2.0));
  return float(double(first) * std::sqrt(r2));
}

// A photon counts towards a surface only if it arrived from the side the normal faces.
PVR_HOST_DEVICE inline bool photonFacesSurface(Vec3 photonDirection, Vec3 n) { return dot(photonDirection, n) < 0.0f; }

// Photons at or past this fraction of the way to the nearest wall lie on it or behind it.
constexpr float kBeyondWall = 0.98f;

// Whether a photon at `offset` from x (its position - x) that arrived along `direction` counts
// towards the estimate at x with unit normal n: it arrived from the side n faces and lies on this
// side of the nearest wall (`wall`: the wall's normal in the tangent plane, pointing into it, over
// its distance; zero: no wall, the paper's sphere).
PVR_HOST_DEVICE inline bool photonCounts(Vec3 offset, Vec3 direction, Vec3 n, Vec3 wall) {
  return photonFacesSurface(direction, n) && dot(offset, wall) < kBeyondWall;
}

// What each photon adds to an estimate: its power, or its power weighted by a view-dependent
// BSDF for its direction (gather.h's GatherPoint::photonContribution).
struct PhotonPower {
  PVR_HOST_DEVICE Vec3 operator()(const Photon& p) const { return p.power; }
};

// The kNN estimate from a filled heap; with fewer than k photons in reach the estimate's support
// is the whole maximum radius (r2).
template <class PhotonMap, class Weigh = PhotonPower>
PVR_HOST_DEVICE Vec3 knnFluxDensity(const PhotonMap& map, const KnnHeap& heap, float r2, const Weigh& weigh = Weigh()) {
  if (heap.size == 0) return {0, 0, 0};
  Vec3 sum{0, 0, 0};
  for (int j = 0; j < heap.size; ++j) sum += weigh(map.photons[heap.index[j]]);
  float area = kPi * (heap.full() ? heap.maxDist2() : r2);
  return area > 0.0f ? sum * (1.0f / area) : Vec3{0, 0, 0};
}

// Flux density sum(weigh(photon)) / (pi r^2) at x on a surface with unit normal n facing the
// viewer; photons that arrived from behind the surface, or lie beyond `wall` (photonCounts), are
// ignored. With PhotonPower it is the irradiance-like sum(dPhi) / (pi r^2): multiply by the
// diffuse BRDF (albedo / pi) for radiance.
template <class PhotonMap, class Weigh = PhotonPower>
PVR_HOST_DEVICE Vec3 estimateFluxDensity(const PhotonMap& map, Vec3 x, Vec3 n, const DensityParams& params,
                                         const Weigh& weigh = Weigh(), Vec3 wall = Vec3{0, 0, 0}) {
  float r2 = params.radius * params.radius;
  if (params.estimator == Estimator::Radius) {
    Vec3 sum{0, 0, 0};
    map.search(x, r2, [&](uint32_t i, float, float&) {
      const Photon& p = map.photons[i];
      if (photonCounts(p.position - x, p.direction, n, wall)) sum += weigh(p);
    });
    return sum * (1.0f / (kPi * r2));
  }
  KnnHeap heap(params.k);
  map.searchNearest(x, r2, [&](uint32_t i, float d2, float& searchR2) {
    const Photon& p = map.photons[i];
    if (photonCounts(p.position - x, p.direction, n, wall)) heap.offer(d2, i, searchR2);
  });
  return knnFluxDensity(map, heap, params.radius * params.radius, weigh);
}

}  // namespace pvr
