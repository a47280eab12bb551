#include "pvr/scene/scene.h"

#include <algorithm>
#include <cmath>

#include "pvr/util/error.h"

namespace pvr {

uint32_t Scene::addMaterial(const Material& m, const std::string& materialName) {
  materials_.push_back(m);
  materialNames_.push_back(materialName);
  return uint32_t(materials_.size() - 1);
}

void Scene::addMesh(const std::string& meshName, const std::vector<Vec3>& vertices, const std::vector<Vec3>& normals,
                    const std::vector<uint32_t>& indices, uint32_t materialId) {
  if (materialId >= materials_.size()) throw Error("mesh '" + meshName + "' refers to a missing material");
  bool withNormals = !normals.empty() && normals.size() == vertices.size();
  if (withNormals && normals_.empty()) normals_.assign(vertices_.size(), Vec3(0.0f));
  uint32_t base = uint32_t(vertices_.size());
  vertices_.insert(vertices_.end(), vertices.begin(), vertices.end());
  if (withNormals) normals_.insert(normals_.end(), normals.begin(), normals.end());
  else if (!normals_.empty()) normals_.resize(vertices_.size(), Vec3(0.0f));  // zero: use geometric normal
  MeshRange range{meshName, triangleCount(), 0};
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    uint32_t i0 = indices[t], i1 = indices[t + 1], i2 = indices[t + 2];
    if (i0 >= vertices.size() || i1 >= vertices.size() || i2 >= vertices.size())
      throw Error("mesh '" + meshName + "' has a vertex index out of range");
    Vec3 a = vertices[i0], b = vertices[i1], c = vertices[i2];
    Vec3 n = cross(b - a, c - a);
    float scale = std::max({lengthSquared(b - a), lengthSquared(c - a), lengthSquared(c - b)});
    if (!isFinite(a) || !isFinite(b) || !isFinite(c) || !(lengthSquared(n) > 1e-12f * scale * scale) ||
        !std::isfinite(lengthSquared(n))) {
      ++skippedTriangles_;
      continue;
    }
    indices_.insert(indices_.end(), {base + i0, base + i1, base + i2});
    materialIds_.push_back(materialId);
    ++range.triangleCount;
  }
  meshes_.push_back(range);
}

void Scene::finalize() {
  if (triangleCount() == 0) throw Error("scene '" + name + "' has no valid triangles");
  // Normals of a mesh without them stay zero: surfacePoint then falls back to the geometric one.
  // Face normals computed once here: the CUDA backend reads the same bits instead of recomputing
  // them with fused multiply-adds, whose tiny +/- residue on axis-aligned faces would flip the
  // sign-dependent tangent frame of Frame::fromNormal and send photons on different paths.
  faceNormals_.resize(triangleCount());
  for (uint32_t t = 0; t < triangleCount(); ++t) {
    Vec3 a = vertices_[indices_[3 * t]], b = vertices_[indices_[3 * t + 1]], c = vertices_[indices_[3 * t + 2]];
    faceNormals_[t] = normalize(cross(b - a, c - a));
  }
  lightTriangles_.clear();
  lightCdf_.assign(1, 0.0f);
  SceneView v = view();
  for (uint32_t t = 0; t < triangleCount(); ++t) {
    const Material& m = materials_[materialIds_[t]];
    if (!m.isEmissive()) continue;
    float w = luminance(m.emission) * v.triangleArea(t);
    if (!(w > 0.0f)) continue;
    lightTriangles_.push_back(t);
    lightCdf_.push_back(lightCdf_.back() + w);
  }
  if (lightTriangles_.empty()) throw Error("scene '" + name + "' has no light (no emissive triangle)");
  Bounds3 b = bounds();
  sceneRadius_ = std::max(0.5f * length(b.extent()), 1e-3f);
}

SceneView Scene::view() const {
  SceneView v;
  v.vertices = vertices_.data();
  v.normals = normals_.empty() ? nullptr : normals_.data();
  v.faceNormals = faceNormals_.empty() ? nullptr : faceNormals_.data();
  v.indices = indices_.data();
  v.materialIds = materialIds_.data();
  v.materials = materials_.data();
  v.triangleCount = triangleCount();
  v.lightTriangles = lightTriangles_.data();
  v.lightCdf = lightCdf_.data();
  v.lightCount = uint32_t(lightTriangles_.size());
  v.sceneRadius = sceneRadius_;
  return v;
}

Bounds3 Scene::bounds() const {
  Bounds3 b;
  for (uint32_t i : indices_) b.extend(vertices_[i]);
  return b;
}

int Scene::meshOfTriangle(uint32_t prim) const {
  for (size_t i = 0; i < meshes_.size(); ++i)
    if (prim >= meshes_[i].firstTriangle && prim < meshes_[i].firstTriangle + meshes_[i].triangleCount) return int(i);
  return -1;
}

Vec3 Scene::totalLightPower() const {
  SceneView v = view();
  Vec3 power{0, 0, 0};
  for (uint32_t t : lightTriangles_) power += materials_[materialIds_[t]].emission * (kPi * v.triangleArea(t));
  return power;
}

}  // namespace pvr
