#pragma once
// How shading/ggx_albedo_table.inc is made (tools/ggx_albedo_table.cpp writes it; a test
// regenerates it and compares): the directional albedo E(mu, alpha) of the GGX reflection lobe
// with Fresnel 1, integrated by stratified sampling of the visible normals, whose weight is
// G2 / G1 exactly (Heitz 2018), and its cosine-weighted mean E_avg = 2 int E(mu) mu dmu.
// 128 x 64 strata per node.
#include <algorithm>
#include <vector>

#include "pvr/shading/ggx_albedo.h"
#include "pvr/shading/microfacet.h"

namespace pvr {

constexpr int kGgxAlbedoStrata = 64;  ///< stratified visible normals per axis and node

// The node coordinates: mu_i = i / (size - 1) (the first at kGgxAlbedoGrazingMu), roughness the
// same, alpha = max(kMinGgxAlpha, roughness^2).
inline float ggxAlbedoNodeMu(int i) { return std::max(kGgxAlbedoGrazingMu, float(i) / float(kGgxAlbedoSize - 1)); }
inline float ggxAlbedoNodeAlpha(int j) {
  const float roughness = float(j) / float(kGgxAlbedoSize - 1);
  return std::max(kMinGgxAlpha, roughness * roughness);
}

// E(mu, alpha): the share of light arriving at cos theta = mu that GGX reflects once, Fresnel 1.
// The visible normals' radial coordinate u1 is stratified through u1 = 1 - (1 - t)^2 (weight
// 2 (1 - t)): the lobe's tail, where reflections start to leave below the horizon, lies at u1 near
// 1, which plain strata would lump into their last one.
inline double integrateGgxAlbedo(float mu, float alpha, int strata = kGgxAlbedoStrata) {
  const Ggx ggx{alpha};
  const Vec3 wo{std::sqrt(std::max(0.0f, 1.0f - mu * mu)), 0.0f, mu};
  const int radial = 2 * strata;
  double sum = 0.0;
  for (int a = 0; a < radial; ++a) {
    const double t = (a + 0.5) / radial, u1 = 1.0 - (1.0 - t) * (1.0 - t), weight = 2.0 * (1.0 - t);
    for (int b = 0; b < strata; ++b) {
      const Vec3 h = ggx.sampleVisibleNormal(wo, float(u1), (float(b) + 0.5f) / float(strata));
      const Vec3 wi = h * (2.0f * dot(wo, h)) - wo;
      if (wi.z > 0.0f) sum += weight * double(ggx.G2(wo.z, wi.z)) / double(ggx.G1(wo.z));
    }
  }
  return sum / (double(radial) * double(strata));
}

// E_avg(alpha) = 2 int_0^1 E(mu) mu dmu by the midpoint rule over `steps` values of mu.
inline double integrateGgxAverageAlbedo(float alpha, int steps = 64, int strata = kGgxAlbedoStrata) {
  double sum = 0.0;
  for (int k = 0; k < steps; ++k) {
    const double mu = (k + 0.5) / steps;
    sum += integrateGgxAlbedo(float(mu), alpha, strata) * mu;
  }
  return 2.0 * sum / steps;
}

// 2 int_0^1 E(mu) mu dmu for E linear between the nodes of one roughness row (exactly, segment by
// segment): the E_avg that makes the multiple-scattering lobe's albedo exactly 1 - E(mu_o) for
// the interpolated table, so that a white metal reflects 1 (bsdf.h).
inline double averageOfInterpolatedAlbedo(const float* row) {
  double sum = 0.0;
  const double step = 1.0 / (kGgxAlbedoSize - 1);
  for (int i = 0; i + 1 < kGgxAlbedoSize; ++i) {
    const double a = i * step, ea = row[i], slope = (double(row[i + 1]) - ea) / step;
    // int_a^{a+step} (ea + slope (mu - a)) mu dmu
    sum += ea * step * (a + 0.5 * step) + slope * step * step * (0.5 * a + step / 3.0);
  }
  return 2.0 * sum;
}

// The table: E at every node, roughness-major ([j * size + i] = E(mu_i, alpha_j)), then E_avg per
// roughness node (of the interpolated rows).
struct GgxAlbedoTable {
  std::vector<float> albedo, averageAlbedo;
};
inline GgxAlbedoTable makeGgxAlbedoTable() {
  GgxAlbedoTable t;
  for (int j = 0; j < kGgxAlbedoSize; ++j)
    for (int i = 0; i < kGgxAlbedoSize; ++i)
      t.albedo.push_back(float(integrateGgxAlbedo(ggxAlbedoNodeMu(i), ggxAlbedoNodeAlpha(j))));
  for (int j = 0; j < kGgxAlbedoSize; ++j)
    t.averageAlbedo.push_back(float(averageOfInterpolatedAlbedo(t.albedo.data() + size_t(j) * kGgxAlbedoSize)));
  return t;
}

}  // namespace pvr
