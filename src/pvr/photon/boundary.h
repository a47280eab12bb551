#pragma once
// The density estimate where a surface meets a wall or ends (Boundary::Clipped). The paper's
// estimate divides the photons within r by pi r^2, but next to a wall part of that disc is not on
// the surface: no photon can land there, so the estimate darkens towards corners, while photons
// on the wall itself that arrived travelling towards the floor's side are counted as if they were
// on the floor. The same holds at convex edges (a table's rim, the open front of the Cornell box:
// on the CPU box, photon-map-only at r = 0.05, the band along its front edges is about 10 % darker
// than the converged image).
//
// Probes find the walls: kWallProbes rays in the tangent plane, at a random rotation, each as long
// as r. They start a quarter of r above the surface, so relief lower than that is not a wall.
// Rays down from a probe's end (and, where they find nothing, halfway and a quarter of the way)
// find where the surface ends. The disc's area on the surface is the sum of the probes' sectors,
// pi r_k^2 / K with r_k the probe's free length (unbiased over the rotation for a disc seen whole
// from its centre), and the estimate is scaled by pi r^2 / area (at most 8x). The nearest wall's
// plane (from its geometric normal) leaves out the photons on it or behind it (photonCounts).
//
// Not corrected: photons on a second wall (a corner of two walls: only the nearest is cut) or on
// the far side of a convex edge that arrived travelling towards this side; kNN's area (the k-th
// distance is known only when estimating; kNN gets the wall's cut alone). Cost: 8 short rays
// along the surface and 8 to 24 down per gather point.
#include "pvr/photon/density.h"
#include "pvr/shading/scene_view.h"
#include "pvr/util/sampling.h"

namespace pvr {

constexpr int kWallProbes = 8;
constexpr float kWallProbeHeight = 0.25f;  ///< of the radius: lower relief is part of the surface
constexpr float kMinDiscShare = 0.125f;    ///< the area correction stops at 8x

struct WallProbe {
  float discShare = 1.0f;  ///< the share of pi r^2 on this side of the walls in reach
  Vec3 wall{0, 0, 0};      ///< the nearest wall as photonCounts takes it; zero: none
};

// Probes around x (unit normal n facing the viewer) within `radius`; u rotates them.
template <class Intersector>
PVR_HOST_DEVICE WallProbe probeWalls(const SceneView& scene, const Intersector& intersector, Vec3 x, Vec3 n, float radius,
                                     float u) {
  WallProbe out;
  const Frame frame = Frame::fromNormal(n);
  const Vec3 origin = x + n * (kWallProbeHeight * radius);
  float area = 0.0f, nearest = radius;
  bool walls = false;
  for (int k = 0; k < kWallProbes; ++k) {
    const float phi = 2.0f * kPi * (float(k) + u) / float(kWallProbes);
    const Vec3 dir = frame.toWorld({cosf(phi), sinf(phi), 0.0f});
    Hit hit;
    float free = radius;
    if (intersector.intersect(Ray{origin, dir}, radius, hit)) {
      walls = true;
      free = hit.t;
      if (hit.t < nearest) {
        // The wall's normal in the tangent plane, pointing into it, over the wall's distance from x.
        Vec3 m = scene.surfacePoint(hit).geometricNormal;
        if (dot(m, dir) < 0.0f) m = -m;
        m = m - n * dot(m, n);
        const float len = length(m);
        m = len > 1e-3f ? m * (1.0f / len) : dir;
        const float distance = dot(dir, m) * hit.t;  // along m to the plane through the hit
        if (distance > 1e-4f * radius) {  // a wall through x itself has no side to cut
          nearest = hit.t;
          out.wall = m * (1.0f / distance);
        }
      }
    }
    // A convex edge: where the surface ends before the probe does, no photon lands beyond it. The
    // surface is looked for under the probe's end, then (two steps of bisection) halfway or a
    // quarter of the way; relief within the probes' height counts as surface.
    auto surfaceBelow = [&](float along) {
      Hit below;
      return intersector.intersect(Ray{origin + dir * along, -n}, 4.0f * kWallProbeHeight * radius, below);
    };
    if (!surfaceBelow(0.98f * free)) {
      walls = true;
      if (surfaceBelow(0.5f * free)) free *= 0.75f;
      else free *= surfaceBelow(0.25f * free) ? 0.375f : 0.125f;
    }
    area += free * free;
  }
  if (walls) out.discShare = fmaxf(area / (float(kWallProbes) * radius * radius), kMinDiscShare);  // else exactly 1
  return out;
}

}  // namespace pvr
