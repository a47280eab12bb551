#pragma once
// A read-only, pointer-based view of the scene for algorithm code on host and device:
// indexed triangles, optional per-vertex normals, per-triangle materials, and the emitting
// triangles with a power-proportional CDF for light sampling and photon emission.
#include "pvr/geometry/ray.h"
#include "pvr/shading/bsdf.h"
#include "pvr/shading/material.h"
#include "pvr/util/sampling.h"

namespace pvr {

// A light without area: glTF's KHR_lights_punctual point and spot lights (intensity in W/sr) and
// a distant (directional) light such as the sun (irradiance in W/m^2 on a surface facing it).
enum class PunctualKind : uint32_t { Point = 0, Spot = 1, Directional = 2 };

struct PunctualLight {
  PunctualKind kind = PunctualKind::Point;
  Vec3 position{0, 0, 0};
  Vec3 direction{0, -1, 0};  ///< unit, the way the light travels (spot axis, sun rays)
  Vec3 intensity{1, 1, 1};   ///< W/sr (point, spot) or W/m^2 (directional)
  float cosInner = 1.0f, cosOuter = 0.0f;  ///< spot cone: full inside inner, none outside outer
  // A distant light's photons cross a disk of this radius around `position`, facing the light
  // (an opening the light comes through, e.g. a courtyard's roof); 0: the scene's bounding sphere.
  float aimRadius = 0.0f;

  // glTF's spot falloff: a smooth step from the outer to the inner cone, squared.
  PVR_HOST_DEVICE float falloff(float cosAngle) const {
    if (kind != PunctualKind::Spot) return 1.0f;
    float scale = 1.0f / fmaxf(1e-3f, cosInner - cosOuter);
    float t = fminf(fmaxf((cosAngle - cosOuter) * scale, 0.0f), 1.0f);
    return t * t;
  }
};

// A uniform sky: radiance L from every direction above the horizon (+y up), none below. Its photons
// cross a disk of aimRadius around aimCenter (an opening such as a courtyard's roof), or the
// scene's bounding sphere when aimRadius is 0.
struct SkyLight {
  Vec3 radiance{0, 0, 0};
  Vec3 aimCenter{0, 0, 0};
  float aimRadius = 0.0f;
  PVR_HOST_DEVICE bool present() const { return !isBlack(radiance); }
  PVR_HOST_DEVICE Vec3 along(Vec3 dir) const { return dir.y > 0.0f ? radiance : Vec3{0, 0, 0}; }
  PVR_HOST_DEVICE float photonRadius(float sceneRadius) const { return aimRadius > 0.0f ? aimRadius : sceneRadius; }
  // The flux that enters a sphere of radius R from the upper hemisphere: L pi R^2 2 pi.
  PVR_HOST_DEVICE Vec3 power(float sceneRadius) const {
    float r = photonRadius(sceneRadius);
    return radiance * (2.0f * kPi * kPi * r * r);
  }
};

// Local geometry at a hit.
struct SurfacePoint {
  Vec3 position;
  Vec3 geometricNormal;  ///< unit, by winding (front face of emitters)
  Vec3 shadingNormal;    ///< unit, interpolated if the mesh has normals, same side as geometricNormal
  uint32_t materialId;
};

struct SceneView {
  const Vec3* vertices = nullptr;
  const Vec3* normals = nullptr;  ///< per vertex, or null
  const Vec3* faceNormals = nullptr;  ///< per triangle, unit, by winding; null: computed on the fly
  const uint32_t* indices = nullptr;  ///< 3 per triangle
  const uint32_t* materialIds = nullptr;
  const Material* materials = nullptr;
  uint32_t triangleCount = 0;
  const Vec2* uvs[2] = {nullptr, nullptr};  ///< per vertex texture coordinates (sets 0, 1), or null
  const TextureView* textures = nullptr;
  uint32_t textureCount = 0;
  const uint32_t* lightTriangles = nullptr;
  // lightCount + 1 entries over the emitting triangles, then the punctual lights, weighted by
  // power / pi: luminance(Le) * area for a triangle, 4 I for a point light, ...
  const float* lightCdf = nullptr;
  uint32_t lightCount = 0;           ///< triangleLightCount + punctualCount (+ 1 with a sky)
  uint32_t triangleLightCount = 0;
  const PunctualLight* punctualLights = nullptr;
  uint32_t punctualCount = 0;
  SkyLight sky;             ///< last in lightCdf when present
  float sceneRadius = 1.0f;  ///< scales ray offsets; the bounding sphere's radius
  Vec3 sceneCenter{0, 0, 0};

  PVR_HOST_DEVICE const Material& material(uint32_t prim) const { return materials[materialIds[prim]]; }

  // A select, not uvs[set]: a run-time index into the array would put a kernel's copy of the
  // whole view in GPU local memory.
  PVR_HOST_DEVICE const Vec2* uvSet(uint32_t set) const { return (set & 1u) ? uvs[1] : uvs[0]; }

  PVR_HOST_DEVICE void triangle(uint32_t prim, Vec3& a, Vec3& b, Vec3& c) const {
    a = vertices[indices[3 * prim]];
    b = vertices[indices[3 * prim + 1]];
    c = vertices[indices[3 * prim + 2]];
  }

  PVR_HOST_DEVICE Vec3 faceNormal(uint32_t prim, Vec3 a, Vec3 b, Vec3 c) const {
    return faceNormals ? faceNormals[prim] : normalize(cross(b - a, c - a));
  }

  PVR_HOST_DEVICE SurfacePoint surfacePoint(const Hit& hit) const {
    Vec3 a, b, c;
    triangle(hit.primId, a, b, c);
    float w = 1.0f - hit.u - hit.v;
    SurfacePoint sp;
    sp.position = a * w + b * hit.u + c * hit.v;
    sp.geometricNormal = faceNormal(hit.primId, a, b, c);
    sp.shadingNormal = sp.geometricNormal;
    if (normals) {
      Vec3 n = normals[indices[3 * hit.primId]] * w + normals[indices[3 * hit.primId + 1]] * hit.u +
               normals[indices[3 * hit.primId + 2]] * hit.v;
      float len = length(n);
      if (len > 0.0f) {
        n = n / len;
        sp.shadingNormal = dot(n, sp.geometricNormal) < 0.0f ? -n : n;
      }
    }
    sp.materialId = materialIds[hit.primId];
    const Material& m = materials[sp.materialId];
    if (m.normalTexture.present()) sp.shadingNormal = normalMapped(m, hit.primId, hit.u, hit.v, sp.shadingNormal, sp.geometricNormal);
    return sp;
  }

  // The shading normal bent by a tangent-space normal map. The tangent frame is the triangle's:
  // T along +u, the second axis up the image (towards -v, as glTF's +Y), both orthogonalised
  // against the interpolated normal. A bent normal that would face away from the surface, or a
  // triangle without a usable UV mapping, keeps the unbent one.
  PVR_HOST_DEVICE Vec3 normalMapped(const Material& m, uint32_t prim, float u, float v, Vec3 n, Vec3 geometric) const {
    const Vec2* t = uvSet(m.normalTexture.texCoord);
    if (!t) return n;
    Vec3 a, b, c;
    triangle(prim, a, b, c);
    Vec2 ta = t[indices[3 * prim]], tb = t[indices[3 * prim + 1]], tc = t[indices[3 * prim + 2]];
    float du1 = tb.x - ta.x, dv1 = tb.y - ta.y, du2 = tc.x - ta.x, dv2 = tc.y - ta.y;
    float det = du1 * dv2 - du2 * dv1;
    if (!(fabsf(det) > 1e-20f)) return n;
    Vec3 e1 = b - a, e2 = c - a;
    Vec3 dpdu = (e1 * dv2 - e2 * dv1) * (1.0f / det), dpdv = (e2 * du1 - e1 * du2) * (1.0f / det);
    Vec3 tangent = dpdu - n * dot(n, dpdu);
    float tl = length(tangent);
    if (!(tl > 0.0f)) return n;
    tangent = tangent * (1.0f / tl);
    Vec3 up = cross(n, tangent);
    if (dot(up, dpdv) > 0.0f) up = -up;  // towards -v: up the image
    Rgba texel = sampleRef(m.normalTexture, prim, u, v, 0.0f);
    float x = (2.0f * texel.rgb.x - 1.0f) * m.normalScale, y = (2.0f * texel.rgb.y - 1.0f) * m.normalScale;
    float z = 2.0f * texel.rgb.z - 1.0f;
    Vec3 bent = tangent * x + up * y + n * z;
    float len = length(bent);
    if (!(len > 0.0f)) return n;
    bent = bent * (1.0f / len);
    return dot(bent, geometric) * dot(n, geometric) > 0.0f ? bent : n;
  }

  PVR_HOST_DEVICE float triangleArea(uint32_t prim) const {
    Vec3 a, b, c;
    triangle(prim, a, b, c);
    return 0.5f * length(cross(b - a, c - a));
  }

  // Texture coordinates of a point (barycentrics u, v) on a triangle; (0, 0) without that set.
  PVR_HOST_DEVICE Vec2 uvAt(uint32_t prim, float u, float v, uint32_t set) const {
    const Vec2* t = uvSet(set);
    if (!t) return {0.0f, 0.0f};
    Vec2 a = t[indices[3 * prim]], b = t[indices[3 * prim + 1]], c = t[indices[3 * prim + 2]];
    float w = 1.0f - u - v;
    return {a.x * w + b.x * u + c.x * v, a.y * w + b.y * u + c.y * v};
  }

  // Area of a triangle in a texture reference's (transformed) UV space.
  PVR_HOST_DEVICE float uvArea(uint32_t prim, const TextureRef& ref) const {
    const Vec2* t = uvSet(ref.texCoord);
    if (!t) return 0.0f;
    Vec2 a = t[indices[3 * prim]], b = t[indices[3 * prim + 1]], c = t[indices[3 * prim + 2]];
    float cross2 = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    return 0.5f * fabsf(cross2 * ref.scale.x * ref.scale.y);
  }

  PVR_HOST_DEVICE Rgba sampleRef(const TextureRef& ref, uint32_t prim, float u, float v, float lod) const {
    return sampleTexture(textures[ref.texture], ref.transform(uvAt(prim, u, v, ref.texCoord)), lod);
  }

  // The level of detail of a texture at a hit seen by a ray cone `coneWidth` wide, arriving at
  // `cosTheta` to the surface (0 when there is no cone: the finest level).
  PVR_HOST_DEVICE float textureLod(const TextureRef& ref, uint32_t prim, float coneWidth, float cosTheta) const {
    if (!(coneWidth > 0.0f)) return 0.0f;
    const TextureView& t = textures[ref.texture];
    return rayConeLod(uvArea(prim, ref), t.width, t.height, triangleArea(prim), coneWidth, cosTheta);
  }

  // A texture at a hit, at the level a ray cone `coneWidth` wide arriving at cosTheta picks.
  PVR_HOST_DEVICE Rgba sampleAtCone(const TextureRef& ref, uint32_t prim, float u, float v, float coneWidth,
                                    float cosTheta) const {
    return sampleRef(ref, prim, u, v, textureLod(ref, prim, coneWidth, cosTheta));
  }

  // The material's colour at a hit: the constant albedo times its base-colour texture.
  PVR_HOST_DEVICE Vec3 albedoAt(const Material& m, uint32_t prim, float u, float v, float coneWidth = 0.0f,
                                float cosTheta = 1.0f) const {
    if (!m.baseColorTexture.present()) return m.albedo;
    return m.albedo * sampleAtCone(m.baseColorTexture, prim, u, v, coneWidth, cosTheta).rgb;
  }

  // A microfacet material's BSDF at a hit seen from wo (unit, away from the surface), its factors
  // multiplied by their textures at the level a ray cone `coneWidth` wide picks. The shading
  // normal is turned to wo's side (every surface is two-sided); one bent past wo by a normal map or
  // interpolation falls back to the geometric normal. Transmission takes the ior on the side wo is not.
  PVR_HOST_DEVICE BsdfParams bsdfAt(const Material& m, const Hit& hit, const SurfacePoint& sp, Vec3 wo,
                                    float coneWidth = 0.0f) const {
    BsdfParams b;
    const bool outside = dot(wo, sp.geometricNormal) > 0.0f;
    const Vec3 nGeo = outside ? sp.geometricNormal : -sp.geometricNormal;
    b.normal = outside ? sp.shadingNormal : -sp.shadingNormal;
    if (!(dot(b.normal, wo) > 1e-4f)) b.normal = nGeo;
    const float cosTheta = dot(wo, nGeo);
    b.baseColor = albedoAt(m, hit.primId, hit.u, hit.v, coneWidth, cosTheta);
    float metallic = m.metallic, roughness = m.roughness;
    if (m.metallicRoughnessTexture.present()) {
      Vec3 t = sampleAtCone(m.metallicRoughnessTexture, hit.primId, hit.u, hit.v, coneWidth, cosTheta).rgb;
      roughness *= t.y;
      metallic *= t.z;
    }
    if (m.shininessTexture.present()) {  // OBJ map_Ns: Blinn-Phong's exponent, matched as alpha = sqrt(2 / (Ns + 2))
      float ns = m.shininess * sampleAtCone(m.shininessTexture, hit.primId, hit.u, hit.v, coneWidth, cosTheta).rgb.x;
      roughness = sqrtf(sqrtf(2.0f / (fmaxf(ns, 0.0f) + 2.0f)));
    }
    b.specularF0 = m.specularF0;
    if (m.specularTexture.present()) {
      b.specularF0 *= luminance(sampleAtCone(m.specularTexture, hit.primId, hit.u, hit.v, coneWidth, cosTheta).rgb);
    }
    b.metallic = fminf(fmaxf(metallic, 0.0f), 1.0f);
    roughness = fminf(fmaxf(roughness, 0.0f), 1.0f);
    b.alpha = fmaxf(kMinGgxAlpha, roughness * roughness);
    b.transmission = m.transmission;
    if (m.transmits()) {
      b.etaO = outside ? 1.0f : m.ior;
      b.etaI = outside ? m.ior : 1.0f;
    }
    return b;
  }

  // Emitted radiance at a point of an emitter's front face: the factor times its emissive texture.
  PVR_HOST_DEVICE Vec3 emissionAt(const Material& m, uint32_t prim, float u, float v, float coneWidth = 0.0f,
                                  float cosTheta = 1.0f) const {
    if (!m.emissiveTexture.present()) return m.emission;
    return m.emission * sampleAtCone(m.emissiveTexture, prim, u, v, coneWidth, cosTheta).rgb;
  }

  // glTF's ambient occlusion factor 1 + strength (texel - 1), 1 without a texture.
  PVR_HOST_DEVICE float occlusionAt(const Material& m, uint32_t prim, float u, float v, float coneWidth = 0.0f,
                                    float cosTheta = 1.0f) const {
    if (!m.occlusionTexture.present()) return 1.0f;
    float ao = sampleAtCone(m.occlusionTexture, prim, u, v, coneWidth, cosTheta).rgb.x;
    return fminf(fmaxf(1.0f + m.occlusionStrength * (ao - 1.0f), 0.0f), 1.0f);
  }

  // Alpha masking: false where the material cuts the surface out (rays pass through). Read at the
  // finest level, the same for eye, shadow and photon rays.
  PVR_HOST_DEVICE bool alphaPasses(uint32_t prim, float u, float v) const {
    const Material& m = material(prim);
    if (!m.alphaTested()) return true;
    float alpha = m.alpha;
    if (m.baseColorTexture.present()) alpha *= sampleRef(m.baseColorTexture, prim, u, v, 0.0f).a;
    if (m.opacityTexture.present()) alpha *= sampleRef(m.opacityTexture, prim, u, v, 0.0f).rgb.x;
    return alpha >= m.alphaCutoff;
  }

  // Offset that keeps a spawned ray off the surface it leaves.
  PVR_HOST_DEVICE float rayEpsilon() const { return 1e-4f * sceneRadius; }
};

// A point sampled on the lights (area lights), or a punctual light chosen.
struct LightSample {
  Vec3 position;
  Vec3 normal;    ///< area: front face
  Vec3 emission;  ///< area: Le; punctual: I (W/sr) or E (W/m^2)
  float pdfArea;  ///< area: probability density per unit area over all light surfaces
  float pick = 1.0f;  ///< probability of choosing this light
  int punctual = -1;  ///< index into punctualLights, or -1 for an area light
  bool sky = false;   ///< the sky was chosen
};

PVR_HOST_DEVICE inline LightSample sampleLight(const SceneView& s, float uPick, float u1, float u2) {
  int i = sampleDiscreteCdf(s.lightCdf, int(s.lightCount), uPick);
  float pick = (s.lightCdf[i + 1] - s.lightCdf[i]) / s.lightCdf[s.lightCount];
  LightSample ls;
  ls.pick = pick;
  if (uint32_t(i) >= s.triangleLightCount + s.punctualCount) {
    ls.sky = true;
    ls.emission = s.sky.radiance;
    ls.pdfArea = 0.0f;
    return ls;
  }
  if (uint32_t(i) >= s.triangleLightCount) {
    ls.punctual = i - int(s.triangleLightCount);
    const PunctualLight& l = s.punctualLights[ls.punctual];
    ls.position = l.position;
    ls.normal = l.direction;
    ls.emission = l.intensity;
    ls.pdfArea = 0.0f;
    return ls;
  }
  uint32_t prim = s.lightTriangles[i];
  Vec3 a, b, c;
  s.triangle(prim, a, b, c);
  Vec2 bc = sampleTriangleBarycentrics(u1, u2);
  float area = 0.5f * length(cross(b - a, c - a));
  ls.position = a * (1.0f - bc.x - bc.y) + b * bc.x + c * bc.y;
  ls.normal = s.faceNormal(prim, a, b, c);
  ls.emission = s.emissionAt(s.material(prim), prim, bc.x, bc.y);
  ls.pdfArea = pick / area;
  return ls;
}

// An area light sample for direct lighting: a triangle chosen among the emitting triangles alone
// (punctual lights are each evaluated exactly, so they need no sampling). With no punctual
// lights this is sampleLight.
PVR_HOST_DEVICE inline LightSample sampleAreaLight(const SceneView& s, float uPick, float u1, float u2) {
  int i = sampleDiscreteCdf(s.lightCdf, int(s.triangleLightCount), uPick);
  float pick = (s.lightCdf[i + 1] - s.lightCdf[i]) / s.lightCdf[s.triangleLightCount];
  uint32_t prim = s.lightTriangles[i];
  Vec3 a, b, c;
  s.triangle(prim, a, b, c);
  Vec2 bc = sampleTriangleBarycentrics(u1, u2);
  float area = 0.5f * length(cross(b - a, c - a));
  LightSample ls;
  ls.pick = pick;
  ls.position = a * (1.0f - bc.x - bc.y) + b * bc.x + c * bc.y;
  ls.normal = s.faceNormal(prim, a, b, c);
  ls.emission = s.emissionAt(s.material(prim), prim, bc.x, bc.y);
  ls.pdfArea = pick / area;
  return ls;
}

// What a punctual light sends to a point: the direction to it, how far a shadow ray must go
// (INFINITY for a distant light) and the irradiance on a surface facing it, already divided by
// the probability of having chosen the light.
struct PunctualIllumination {
  Vec3 wi{0, 0, 0};
  float shadowDistance = 0.0f;
  Vec3 irradiance{0, 0, 0};
};

PVR_HOST_DEVICE inline PunctualIllumination illuminate(const SceneView& s, const LightSample& ls, Vec3 p, float eps) {
  const PunctualLight& l = s.punctualLights[ls.punctual];
  PunctualIllumination out;
  if (l.kind == PunctualKind::Directional) {
    out.wi = -l.direction;
    out.shadowDistance = INFINITY;
    out.irradiance = l.intensity * (1.0f / ls.pick);
    return out;
  }
  Vec3 toLight = l.position - p;
  float dist2 = lengthSquared(toLight);
  if (!(dist2 > 0.0f)) return out;
  float dist = sqrtf(dist2);
  out.wi = toLight / dist;
  out.shadowDistance = dist * (1.0f - 1e-3f) - eps;
  out.irradiance = l.intensity * (l.falloff(-dot(out.wi, l.direction)) / (dist2 * ls.pick));
  return out;
}

// The power a punctual light emits (W): 4 pi I, the spot's falloff integrated over its cone, or
// E times the scene's cross-section for a distant light.
PVR_HOST_DEVICE inline Vec3 punctualPower(const PunctualLight& l, float sceneRadius) {
  if (l.kind == PunctualKind::Directional) {
    float r = l.aimRadius > 0.0f ? l.aimRadius : sceneRadius;
    return l.intensity * (kPi * r * r);
  }
  if (l.kind == PunctualKind::Point) return l.intensity * (4.0f * kPi);
  // 2 pi times the integral of the falloff over cos(angle) from cosOuter to 1 (midpoint rule).
  const int n = 256;
  float sum = 0.0f, step = (1.0f - l.cosOuter) / float(n);
  for (int k = 0; k < n; ++k) sum += l.falloff(l.cosOuter + (float(k) + 0.5f) * step);
  return l.intensity * (2.0f * kPi * sum * step);
}

}  // namespace pvr
