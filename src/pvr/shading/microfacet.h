#pragma once
// The GGX (Trowbridge-Reitz) microfacet distribution, isotropic, in a local frame whose normal is
// +z: the normal distribution D, Smith's masking G1 and height-correlated masking-shadowing G2, and
// sampling of the normals visible from a direction (Heitz 2018, "Sampling the GGX Distribution of
// Visible Normals"), whose pdf is G1(wo) max(0, wo.h) D(h) / wo.z.
#include "pvr/math/vec.h"

namespace pvr {

// Below this alpha (roughness^2) the lobe is treated as this sharp: D stays finite in float.
constexpr float kMinGgxAlpha = 1e-3f;

struct Ggx {
  float alpha = 1.0f;

  // D at a microfacet normal at cosH to the normal, sin2H = 1 - cosH^2 passed in as computed from
  // the tangential components: 1 - cosH^2 in float cancels to noise for sharp lobes.
  PVR_HOST_DEVICE float D(float cosH, float sin2H) const {
    if (!(cosH > 0.0f)) return 0.0f;
    float a2 = alpha * alpha;
    float d = a2 * cosH * cosH + sin2H;
    return a2 / (kPi * d * d);
  }
  PVR_HOST_DEVICE float D(Vec3 hLocal) const { return D(hLocal.z, hLocal.x * hLocal.x + hLocal.y * hLocal.y); }
  // D at a world-space microfacet normal h about the unit normal n.
  PVR_HOST_DEVICE float D(Vec3 n, Vec3 h) const {
    float c = dot(n, h);
    return D(c, lengthSquared(h - n * c));
  }

  // Smith's Lambda for a direction at |cosTheta| to the normal.
  PVR_HOST_DEVICE float lambda(float cosTheta) const {
    float c2 = cosTheta * cosTheta;
    if (!(c2 > 0.0f)) return 1e30f;
    float tan2 = fmaxf(0.0f, 1.0f - c2) / c2;
    return 0.5f * (sqrtf(1.0f + alpha * alpha * tan2) - 1.0f);
  }

  PVR_HOST_DEVICE float G1(float cosTheta) const { return 1.0f / (1.0f + lambda(cosTheta)); }
  PVR_HOST_DEVICE float G2(float cosO, float cosI) const { return 1.0f / (1.0f + lambda(cosO) + lambda(cosI)); }

  // Density of the visible normal h seen from wo (both local, wo.z > 0).
  PVR_HOST_DEVICE float visibleNormalPdf(Vec3 wo, Vec3 h) const {
    float c = dot(wo, h);
    if (!(c > 0.0f) || !(wo.z > 0.0f)) return 0.0f;
    return G1(wo.z) * c * D(h) / wo.z;
  }

  // A visible normal seen from wo (local, wo.z > 0).
  PVR_HOST_DEVICE Vec3 sampleVisibleNormal(Vec3 wo, float u1, float u2) const {
    Vec3 vh = normalize(Vec3{alpha * wo.x, alpha * wo.y, wo.z});  // the view in the hemisphere configuration
    float lenSq = vh.x * vh.x + vh.y * vh.y;
    Vec3 t1 = lenSq > 0.0f ? Vec3{-vh.y, vh.x, 0.0f} * (1.0f / sqrtf(lenSq)) : Vec3{1.0f, 0.0f, 0.0f};
    Vec3 t2 = cross(vh, t1);
    float r = sqrtf(u1), phi = 2.0f * kPi * u2;
    float p1 = r * cosf(phi), p2 = r * sinf(phi);
    float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * sqrtf(fmaxf(0.0f, 1.0f - p1 * p1)) + s * p2;
    Vec3 nh = t1 * p1 + t2 * p2 + vh * sqrtf(fmaxf(0.0f, 1.0f - p1 * p1 - p2 * p2));
    return normalize(Vec3{alpha * nh.x, alpha * nh.y, fmaxf(1e-7f, nh.z)});
  }
};

// Schlick's Fresnel approximation between the reflectances at normal (f0) and grazing (f90) incidence.
PVR_HOST_DEVICE inline float schlickWeight(float cosTheta) {
  float m = fminf(fmaxf(1.0f - cosTheta, 0.0f), 1.0f);
  float m2 = m * m;
  return m2 * m2 * m;
}

}  // namespace pvr
