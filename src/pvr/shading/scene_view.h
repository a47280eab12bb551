#pragma once
// A read-only, pointer-based view of the scene for algorithm code on host and device:
// indexed triangles, optional per-vertex normals, per-triangle materials, and the emitting
// triangles with a power-proportional CDF for light sampling and photon emission.
#include "pvr/geometry/ray.h"
#include "pvr/shading/material.h"
#include "pvr/util/sampling.h"

namespace pvr {

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
  const float* lightCdf = nullptr;  ///< lightCount + 1 entries, weights luminance(Le) * area
  uint32_t lightCount = 0;
  float sceneRadius = 1.0f;  ///< scales ray offsets

  PVR_HOST_DEVICE const Material& material(uint32_t prim) const { return materials[materialIds[prim]]; }

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
    return sp;
  }

  PVR_HOST_DEVICE float triangleArea(uint32_t prim) const {
    Vec3 a, b, c;
    triangle(prim, a, b, c);
    return 0.5f * length(cross(b - a, c - a));
  }

  // Texture coordinates of a point (barycentrics u, v) on a triangle; (0, 0) without that set.
  PVR_HOST_DEVICE Vec2 uvAt(uint32_t prim, float u, float v, uint32_t set) const {
    const Vec2* t = uvs[set & 1u];
    if (!t) return {0.0f, 0.0f};
    Vec2 a = t[indices[3 * prim]], b = t[indices[3 * prim + 1]], c = t[indices[3 * prim + 2]];
    float w = 1.0f - u - v;
    return {a.x * w + b.x * u + c.x * v, a.y * w + b.y * u + c.y * v};
  }

  // Area of a triangle in a texture reference's (transformed) UV space.
  PVR_HOST_DEVICE float uvArea(uint32_t prim, const TextureRef& ref) const {
    const Vec2* t = uvs[ref.texCoord & 1u];
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

  // The material's colour at a hit: the constant albedo times its base-colour texture.
  PVR_HOST_DEVICE Vec3 albedoAt(const Material& m, uint32_t prim, float u, float v, float coneWidth = 0.0f,
                                float cosTheta = 1.0f) const {
    if (!m.baseColorTexture.present()) return m.albedo;
    float lod = textureLod(m.baseColorTexture, prim, coneWidth, cosTheta);
    return m.albedo * sampleRef(m.baseColorTexture, prim, u, v, lod).rgb;
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

// A point sampled on the lights.
struct LightSample {
  Vec3 position;
  Vec3 normal;    ///< front face
  Vec3 emission;  ///< Le
  float pdfArea;  ///< probability density per unit area over all light surfaces
};

PVR_HOST_DEVICE inline LightSample sampleLight(const SceneView& s, float uPick, float u1, float u2) {
  int i = sampleDiscreteCdf(s.lightCdf, int(s.lightCount), uPick);
  uint32_t prim = s.lightTriangles[i];
  Vec3 a, b, c;
  s.triangle(prim, a, b, c);
  Vec2 bc = sampleTriangleBarycentrics(u1, u2);
  float area = 0.5f * length(cross(b - a, c - a));
  LightSample ls;
  ls.position = a * (1.0f - bc.x - bc.y) + b * bc.x + c * bc.y;
  ls.normal = s.faceNormal(prim, a, b, c);
  ls.emission = s.material(prim).emission;
  float pick = (s.lightCdf[i + 1] - s.lightCdf[i]) / s.lightCdf[s.lightCount];
  ls.pdfArea = pick / area;
  return ls;
}

}  // namespace pvr
