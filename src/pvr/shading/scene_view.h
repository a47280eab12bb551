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
