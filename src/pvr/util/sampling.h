#pragma once
// Warps of uniform numbers to the distributions photon tracing and shading need.
#include "pvr/math/vec.h"

namespace pvr {

// Cosine-weighted direction about +z; pdf = cos(theta) / pi.
PVR_HOST_DEVICE inline Vec3 sampleCosineHemisphere(float u1, float u2) {
  float r = sqrtf(u1);
  float phi = 2.0f * kPi * u2;
  return {r * cosf(phi), r * sinf(phi), sqrtf(fmaxf(0.0f, 1.0f - u1))};
}

// Uniform point on a triangle as barycentrics (b1, b2); b0 = 1 - b1 - b2.
PVR_HOST_DEVICE inline Vec2 sampleTriangleBarycentrics(float u1, float u2) {
  float s = sqrtf(u1);
  return {1.0f - s, u2 * s};
}

// Index i with cdf[i] <= u * total < cdf[i + 1]; cdf has n + 1 entries, cdf[0] = 0.
PVR_HOST_DEVICE inline int sampleDiscreteCdf(const float* cdf, int n, float u) {
  float target = u * cdf[n];
  int lo = 0, hi = n - 1;
  while (lo < hi) {
    int mid = (lo + hi + 1) / 2;
    if (cdf[mid] <= target) lo = mid;
    else hi = mid - 1;
  }
  return lo;
}

}  // namespace pvr
