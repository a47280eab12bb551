#pragma once
// Surface materials: Lambertian diffuse (where photons are stored), perfect mirror and smooth
// dielectric (glass). Any material may also emit (an area light). The colour may come from a
// texture (times the constant factor), and an alpha mask may cut texels out of the surface.
#include "pvr/math/vec.h"
#include "pvr/shading/texture.h"

namespace pvr {

enum class MaterialType : uint32_t { Diffuse = 0, Mirror = 1, Glass = 2 };

// glTF's alphaMode. BLEND is treated as MASK at the cutoff (a ray tracer's surfaces are opaque
// or absent; stochastic transparency would be noisier, not more right): docs/scene-format.md.
enum class AlphaMode : uint32_t { Opaque = 0, Mask = 1, Blend = 2 };

struct Material {
  MaterialType type = MaterialType::Diffuse;
  Vec3 albedo{0.8f, 0.8f, 0.8f};  ///< diffuse albedo, mirror reflectance or glass transmittance tint
  Vec3 emission{0, 0, 0};         ///< emitted radiance Le from the front face (W / m^2 / sr)
  float ior = 1.5f;               ///< index of refraction (glass only)
  TextureRef baseColorTexture;    ///< multiplies albedo (RGB) and alpha (A)
  TextureRef opacityTexture;      ///< OBJ's map_d: alpha from its first channel
  TextureRef normalTexture;       ///< tangent-space normal map (glTF's convention: +X along +u, +Y up the image)
  float normalScale = 1.0f;       ///< glTF's normalTexture.scale: multiplies the map's X and Y
  AlphaMode alphaMode = AlphaMode::Opaque;
  float alpha = 1.0f;             ///< baseColorFactor's alpha
  float alphaCutoff = 0.5f;       ///< MASK: texels with alpha below this are cut out

  PVR_HOST_DEVICE bool alphaTested() const { return alphaMode != AlphaMode::Opaque; }

  PVR_HOST_DEVICE bool isSpecular() const { return type != MaterialType::Diffuse; }
  PVR_HOST_DEVICE bool isEmissive() const { return !isBlack(emission); }
};

// Unpolarized Fresnel reflectance of a smooth dielectric; cosI > 0, eta = n_incident / n_transmitted.
PVR_HOST_DEVICE inline float fresnelDielectric(float cosI, float eta, float& cosT) {
  float sin2T = eta * eta * fmaxf(0.0f, 1.0f - cosI * cosI);
  if (sin2T >= 1.0f) {
    cosT = 0.0f;
    return 1.0f;  // total internal reflection
  }
  cosT = sqrtf(1.0f - sin2T);
  float rs = (eta * cosI - cosT) / (eta * cosI + cosT);
  float rp = (cosI - eta * cosT) / (cosI + eta * cosT);
  return 0.5f * (rs * rs + rp * rp);
}

// Continues a path at a specular surface. `dir` points along the travel direction, `n` is the
// shading normal (any side). The choice between reflection and refraction is made with
// probability F, so the throughput update is the tint alone (the Fresnel weight cancels).
PVR_HOST_DEVICE inline Vec3 scatterSpecular(const Material& m, Vec3 dir, Vec3 n, float u, Vec3& throughput) {
  if (m.type == MaterialType::Mirror) {
    throughput *= m.albedo;
    return reflect(dir, n);
  }
  bool entering = dot(dir, n) < 0.0f;
  Vec3 nf = entering ? n : -n;  // faces the incoming side
  float eta = entering ? 1.0f / m.ior : m.ior;
  float cosI = -dot(dir, nf);
  float cosT;
  float f = fresnelDielectric(cosI, eta, cosT);
  if (u < f) return reflect(dir, nf);
  throughput *= m.albedo;
  return normalize(dir * eta + nf * (eta * cosI - cosT));
}

}  // namespace pvr
