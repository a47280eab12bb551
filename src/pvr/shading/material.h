#pragma once
// Surface materials: Lambertian diffuse, perfect mirror, smooth dielectric (glass), and glTF's
// metallic-roughness microfacet material (shading/bsdf.h: GGX metals, glossy dielectrics, rough
// glass). Photons are stored on every surface that is not a mirror or smooth glass. Any material
// may also emit (an area light). Factors may be multiplied by textures, and an alpha mask may cut
// texels out of the surface.
#include <array>

#include "pvr/math/vec.h"
#include "pvr/shading/texture.h"

namespace pvr {

enum class MaterialType : uint32_t { Diffuse = 0, Mirror = 1, Glass = 2, Microfacet = 3 };

// glTF's alphaMode. BLEND is treated as MASK at the cutoff (a ray tracer's surfaces are opaque
// or absent; stochastic transparency would be noisier, not more right): docs/scene-format.md.
enum class AlphaMode : uint32_t { Opaque = 0, Mask = 1, Blend = 2 };

// Ray-VR's per-material effect levels (its section IV-B), extended with photon mapping: how much
// of the light transport a surface gets, cheapest first. Each level adds to the one before.
enum class EffectLevel : uint32_t {
  Raster = 0,       ///< emission and direct light, unshadowed; mirrors and glass shaded by their tint, not followed
  Shadows = 1,      ///< direct light by shadow rays
  Reflections = 2,  ///< mirrors, glass and sharp glossy lobes followed, shadowed direct light where they end
  Gi = 3,           ///< photon-mapped caustics and indirect light (the default: the main paper's shading)
  Path = 4,         ///< indirect light path traced instead (next-event estimation, Russian roulette)
};
constexpr int kEffectLevels = 5;
// Materials fall into effect groups (Ray-VR's "statues and wall decorations"): a scene names up
// to this many, group 0 being every material no group names; RenderOptions may set each group's
// level at run time (GatherParams::groupEffects), as the budget controller does.
constexpr int kMaxEffectGroups = 8;
constexpr uint8_t kOwnEffectLevel = 0xFF;  ///< a group whose materials keep their own levels
PVR_HOST_DEVICE constexpr const char* effectLevelName(EffectLevel level) {
  return level == EffectLevel::Raster ? "raster" : level == EffectLevel::Shadows ? "shadows"
         : level == EffectLevel::Reflections ? "reflections" : level == EffectLevel::Gi ? "gi" : "path";
}

struct Material {
  MaterialType type = MaterialType::Diffuse;
  Vec3 albedo{0.8f, 0.8f, 0.8f};  ///< diffuse albedo, mirror reflectance or glass transmittance tint
  Vec3 emission{0, 0, 0};         ///< emitted radiance Le from the front face (W / m^2 / sr)
  float ior = 1.5f;               ///< index of refraction (glass, microfacet transmission)
  // Microfacet only (glTF's metallic-roughness model):
  float metallic = 0.0f;
  float roughness = 1.0f;         ///< perceptual roughness; GGX alpha = roughness^2
  float transmission = 0.0f;      ///< KHR_materials_transmission: the non-metal's share that refracts
  float specularF0 = 0.04f;       ///< dielectric reflectance at normal incidence (from the ior, or OBJ Ks)
  float occlusionStrength = 1.0f; ///< glTF occlusionTexture.strength
  TextureRef metallicRoughnessTexture;  ///< roughness in G, metallic in B (glTF), multiplying the factors
  TextureRef emissiveTexture;     ///< multiplies emission (RGB)
  TextureRef occlusionTexture;    ///< baked ambient occlusion (R): darkens the photon-map term only
  TextureRef specularTexture;     ///< OBJ map_Ks: multiplies specularF0 (its luminance)
  TextureRef shininessTexture;    ///< OBJ map_Ns: multiplies the Phong exponent (R, 0..1)
  float shininess = 0.0f;         ///< the Phong exponent Ns that map_Ns scales
  TextureRef baseColorTexture;    ///< multiplies albedo (RGB) and alpha (A)
  TextureRef opacityTexture;      ///< OBJ's map_d: alpha from its first channel
  TextureRef normalTexture;       ///< tangent-space normal map (glTF's convention: +X along +u, +Y up the image)
  float normalScale = 1.0f;       ///< glTF's normalTexture.scale: multiplies the map's X and Y
  AlphaMode alphaMode = AlphaMode::Opaque;
  float alpha = 1.0f;             ///< baseColorFactor's alpha
  float alphaCutoff = 0.5f;       ///< MASK: texels with alpha below this are cut out
  EffectLevel effect = EffectLevel::Gi;  ///< what the eye paths do at this surface (RenderOptions may override it)
  uint32_t effectGroup = 0;              ///< its effect group (Scene::effectGroupNames), below kMaxEffectGroups

  // Every texture reference, for validation.
  std::array<const TextureRef*, 8> textureRefs() const {
    return {&baseColorTexture, &opacityTexture, &normalTexture, &metallicRoughnessTexture, &emissiveTexture,
            &occlusionTexture, &specularTexture, &shininessTexture};
  }

  PVR_HOST_DEVICE bool alphaTested() const { return alphaMode != AlphaMode::Opaque; }

  /// A mirror or smooth glass: a delta BSDF, followed by the paths, never storing photons.
  PVR_HOST_DEVICE bool isSpecular() const { return type == MaterialType::Mirror || type == MaterialType::Glass; }
  /// Sends the same radiance in every direction (Lambertian): what stereo reuse may share.
  PVR_HOST_DEVICE bool isViewIndependent() const { return type == MaterialType::Diffuse; }
  PVR_HOST_DEVICE bool isEmissive() const { return !isBlack(emission); }
  /// Microfacet materials with a refracting share need rays and lights from both sides.
  PVR_HOST_DEVICE bool transmits() const { return type == MaterialType::Microfacet && transmission > 0.0f; }
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
