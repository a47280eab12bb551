#pragma once
// The GGX reflection lobe's directional albedo E(mu, alpha) with Fresnel 1 and its cosine-weighted
// mean E_avg(alpha), tabulated (shading/ggx_albedo_generator.h made the table; a test checks it)
// and interpolated: what Kulla and Conty's (2017) multiple-scattering lobe (shading/bsdf.h) gives
// back of the energy a single microfacet bounce loses.
#include "pvr/math/vec.h"

namespace pvr {

constexpr int kGgxAlbedoSize = 32;            ///< nodes per axis: mu and perceptual roughness, 0..1 inclusive
constexpr float kGgxAlbedoGrazingMu = 1e-3f;  ///< the mu the first node stands for (E's limit at grazing)

#include "pvr/shading/ggx_albedo_table.inc"

inline constexpr float kGgxAlbedoTable[kGgxAlbedoSize * kGgxAlbedoSize] = {PVR_GGX_ALBEDO};
inline constexpr float kGgxAverageAlbedoTable[kGgxAlbedoSize] = {PVR_GGX_AVERAGE_ALBEDO};
#ifdef __CUDACC__
// Device code cannot read a host constexpr array: the same values in device memory (4 KB per
// translation unit, read through the read-only cache).
static __device__ const float kGgxAlbedoTableDevice[kGgxAlbedoSize * kGgxAlbedoSize] = {PVR_GGX_ALBEDO};
static __device__ const float kGgxAverageAlbedoTableDevice[kGgxAlbedoSize] = {PVR_GGX_AVERAGE_ALBEDO};
#endif

PVR_HOST_DEVICE inline float ggxAlbedoNode(int mu, int roughness) {
  const int i = roughness * kGgxAlbedoSize + mu;
#ifdef __CUDA_ARCH__
  return __ldg(&kGgxAlbedoTableDevice[i]);
#else
  return kGgxAlbedoTable[i];
#endif
}

PVR_HOST_DEVICE inline float ggxAverageAlbedoNode(int roughness) {
#ifdef __CUDA_ARCH__
  return __ldg(&kGgxAverageAlbedoTableDevice[roughness]);
#else
  return kGgxAverageAlbedoTable[roughness];
#endif
}

// A coordinate in [0, 1] as a node index and the fraction towards the next node.
PVR_HOST_DEVICE inline int ggxAlbedoCell(float x, float& fraction) {
  const float scaled = fminf(fmaxf(x, 0.0f), 1.0f) * float(kGgxAlbedoSize - 1);
  const int cell = int(scaled) < kGgxAlbedoSize - 2 ? int(scaled) : kGgxAlbedoSize - 2;
  fraction = scaled - float(cell);
  return cell;
}

// E(mu, alpha), bilinear in mu and the perceptual roughness sqrt(alpha).
PVR_HOST_DEVICE inline float ggxAlbedo(float mu, float alpha) {
  float fm, fr;
  const int i = ggxAlbedoCell(mu, fm), j = ggxAlbedoCell(sqrtf(alpha), fr);
  const float lower = ggxAlbedoNode(i, j) + (ggxAlbedoNode(i + 1, j) - ggxAlbedoNode(i, j)) * fm;
  const float upper = ggxAlbedoNode(i, j + 1) + (ggxAlbedoNode(i + 1, j + 1) - ggxAlbedoNode(i, j + 1)) * fm;
  return lower + (upper - lower) * fr;
}

// E_avg(alpha), linear in the perceptual roughness.
PVR_HOST_DEVICE inline float ggxAverageAlbedo(float alpha) {
  float fr;
  const int j = ggxAlbedoCell(sqrtf(alpha), fr);
  return ggxAverageAlbedoNode(j) + (ggxAverageAlbedoNode(j + 1) - ggxAverageAlbedoNode(j)) * fr;
}

}  // namespace pvr
