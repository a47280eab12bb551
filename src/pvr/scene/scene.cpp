#include "pvr/scene/scene.h"

#include <algorithm>
#include <cmath>

#include "pvr/util/error.h"
#include "pvr/util/input_limits.h"

namespace pvr {

uint32_t Scene::addMaterial(const Material& m, const std::string& materialName) {
  materials_.push_back(m);
  materialNames_.push_back(materialName);
  return uint32_t(materials_.size() - 1);
}

uint32_t Scene::addEffectGroup(const std::string& groupName) {
  if (effectGroupIndex(groupName) >= 0) throw Error("effect group '" + groupName + "' is named twice");
  if (effectGroupNames_.size() >= size_t(kMaxEffectGroups))
    throw Error("more than " + std::to_string(kMaxEffectGroups - 1) + " effect groups");
  effectGroupNames_.push_back(groupName);
  return uint32_t(effectGroupNames_.size() - 1);
}

void Scene::setEffectGroup(uint32_t material, uint32_t group) {
  if (group >= effectGroupNames_.size()) throw Error("no effect group " + std::to_string(group));
  materials_.at(material).effectGroup = group;
}

int Scene::effectGroupIndex(const std::string& groupName) const {
  auto it = std::find(effectGroupNames_.begin(), effectGroupNames_.end(), groupName);
  return it == effectGroupNames_.end() ? -1 : int(it - effectGroupNames_.begin());
}

int Scene::materialIndex(const std::string& materialName) const {
  auto it = std::find(materialNames_.begin(), materialNames_.end(), materialName);
  return it == materialNames_.end() ? -1 : int(it - materialNames_.begin());
}

void Scene::addMesh(const std::string& meshName, const std::vector<Vec3>& vertices, const std::vector<Vec3>& normals,
                    const std::vector<uint32_t>& indices, uint32_t materialId) {
  static const std::vector<Vec2> none[2];
  addMesh(meshName, vertices, normals, none, indices, materialId);
}

void Scene::addMesh(const std::string& meshName, const std::vector<Vec3>& vertices, const std::vector<Vec3>& normals,
                    const std::vector<Vec2> (&uvs)[2], const std::vector<uint32_t>& indices, uint32_t materialId) {
  if (materialId >= materials_.size()) throw Error("mesh '" + meshName + "' refers to a missing material");
  for (int set = 0; set < 2; ++set) {  // sets missing on earlier meshes are zero for them
    bool with = uvs[set].size() == vertices.size() && !vertices.empty();
    if (with && uvs_[set].empty()) uvs_[set].assign(vertices_.size(), Vec2{});
    if (with) {
      for (Vec2 uv : uvs[set])
        uvs_[set].push_back(std::isfinite(uv.x) && std::isfinite(uv.y) ? uv : Vec2{});
    } else if (!uvs_[set].empty()) {
      uvs_[set].resize(vertices_.size() + vertices.size(), Vec2{});
    }
  }
  bool withNormals = !normals.empty() && normals.size() == vertices.size();
  if (withNormals && normals_.empty()) normals_.assign(vertices_.size(), Vec3(0.0f));
  uint32_t base = uint32_t(vertices_.size());
  vertices_.insert(vertices_.end(), vertices.begin(), vertices.end());
  if (withNormals) normals_.insert(normals_.end(), normals.begin(), normals.end());
  else if (!normals_.empty()) normals_.resize(vertices_.size(), Vec3(0.0f));  // zero: use geometric normal
  const uint64_t maxTriangles = inputLimits().triangles;
  if (uint64_t(triangleCount()) + indices.size() / 3 > maxTriangles)
    throw Error("mesh '" + meshName + "' brings the scene to " + std::to_string(uint64_t(triangleCount()) + indices.size() / 3) +
                " triangles: at most " + std::to_string(maxTriangles));
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
  for (size_t i = 0; i < materials_.size(); ++i)
    for (const TextureRef* ref : materials_[i].textureRefs())
      if (ref->texture >= int32_t(textures_.size()))
        throw Error("material '" + materialNames_[i] + "' refers to a missing texture");
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
  Bounds3 b = bounds();
  sceneRadius_ = std::max(0.5f * length(b.extent()), 1e-3f);
  sceneCenter_ = (b.lower + b.upper) * 0.5f;
  // Punctual lights after the triangles, weighted on the same scale (power / pi).
  for (const PunctualLight& l : punctualLights_) {
    float w = luminance(punctualPower(l, sceneRadius_)) / kPi;
    lightCdf_.push_back(lightCdf_.back() + (w > 0.0f ? w : 0.0f));
  }
  if (sky_.present()) lightCdf_.push_back(lightCdf_.back() + luminance(sky_.power(sceneRadius_)) / kPi);
  if (!(lightCdf_.back() > 0.0f))
    throw Error("scene '" + name + "' has no light (no emissive triangle, no point, spot or sun light, no sky)");
}

uint32_t Scene::addTexture(const std::string& textureName, int width, int height, std::vector<uint32_t> rgba, bool srgb,
                           WrapMode wrapS, WrapMode wrapT) {
  const InputLimits& limits = inputLimits();
  if (width <= 0 || height <= 0 || rgba.size() != size_t(width) * size_t(height))
    throw Error("texture '" + textureName + "' has a bad size (" + std::to_string(width) + "x" + std::to_string(height) + ")");
  if (width > limits.textureSide || height > limits.textureSide)
    throw Error("texture '" + textureName + "' is " + std::to_string(width) + "x" + std::to_string(height) + ": at most " +
                std::to_string(limits.textureSide) + " texels per side");
  if (textures_.size() >= limits.textures)
    throw Error("texture '" + textureName + "': a scene has at most " + std::to_string(limits.textures) + " textures");
  uint64_t bytes = 0;
  for (const std::vector<uint32_t>& held : textureTexels_) bytes += held.size() * sizeof(uint32_t);
  bytes += uint64_t(width) * uint64_t(height) * sizeof(uint32_t) * 4 / 3;  // with its mip levels
  if (bytes > limits.textureBytes)
    throw Error("texture '" + textureName + "': the scene's textures would take " + std::to_string(bytes >> 20) +
                " MiB with their mip levels, at most " + std::to_string(limits.textureBytes >> 20) + " MiB");
  TextureView t;
  t.width = width, t.height = height;
  t.wrapS = wrapS, t.wrapT = wrapT;
  t.srgb = srgb;
  std::vector<uint32_t> texels = std::move(rgba);
  auto toLinear = [&](uint32_t code) { return srgb ? srgb8ToLinear(code) : float(code) / 255.0f; };
  auto toCode = [&](float v) {
    v = std::clamp(v, 0.0f, 1.0f);
    if (srgb) v = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
    return uint32_t(std::lround(255.0f * v));
  };
  int w = width, h = height, level = 0;
  t.levelOffset[0] = 0;
  for (;;) {
    ++level;
    if ((w == 1 && h == 1) || level == kMaxTextureLevels) break;
    // Each texel of the next level averages the 2x2 (or 2x1, 1x2) texels under it, in linear light.
    int nw = std::max(w / 2, 1), nh = std::max(h / 2, 1);
    size_t src = t.levelOffset[level - 1];
    t.levelOffset[level] = uint32_t(texels.size());
    for (int y = 0; y < nh; ++y)
      for (int x = 0; x < nw; ++x) {
        float sum[4] = {0, 0, 0, 0};
        int n = 0;
        for (int dy = 0; dy < (h > 1 ? 2 : 1); ++dy)
          for (int dx = 0; dx < (w > 1 ? 2 : 1); ++dx, ++n) {
            uint32_t c = texels[src + size_t(std::min(2 * y + dy, h - 1)) * w + std::min(2 * x + dx, w - 1)];
            for (int k = 0; k < 3; ++k) sum[k] += toLinear((c >> (8 * k)) & 255u);
            sum[3] += float(c >> 24) / 255.0f;
          }
        uint32_t out = 0;
        for (int k = 0; k < 3; ++k) out |= toCode(sum[k] / float(n)) << (8 * k);
        out |= uint32_t(std::lround(255.0f * std::clamp(sum[3] / float(n), 0.0f, 1.0f))) << 24;
        texels.push_back(out);
      }
    w = nw, h = nh;
  }
  t.levels = level;
  textureTexels_.push_back(std::move(texels));
  textures_.push_back(t);
  for (size_t i = 0; i < textures_.size(); ++i) textures_[i].texels = textureTexels_[i].data();  // may have moved
  return uint32_t(textures_.size() - 1);
}

void Scene::setSky(const SkyLight& sky) {
  if (!isFinite(sky.radiance) || !isFinite(sky.aimCenter) || !std::isfinite(sky.aimRadius))
    throw Error("the sky has a non-finite radiance or aim");
  if (sky.radiance.x < 0 || sky.radiance.y < 0 || sky.radiance.z < 0) throw Error("the sky's radiance must not be negative");
  if (sky.aimRadius < 0) throw Error("the sky's aim_radius must be positive");
  sky_ = sky;
}

uint32_t Scene::addPunctualLight(const PunctualLight& light, const std::string& lightName) {
  PunctualLight l = light;
  const std::string what = "light '" + lightName + "'";
  if (!isFinite(l.position) || !isFinite(l.direction) || !isFinite(l.intensity))
    throw Error(what + " has a non-finite position, direction or intensity");
  if (l.intensity.x < 0 || l.intensity.y < 0 || l.intensity.z < 0) throw Error(what + " has a negative intensity");
  if (l.kind != PunctualKind::Point) {
    if (!(lengthSquared(l.direction) > 0.0f)) throw Error(what + " has no direction");
    l.direction = normalize(l.direction);
  }
  if (l.kind == PunctualKind::Spot && !(l.cosOuter >= 0.0f && l.cosOuter < 1.0f && l.cosInner >= l.cosOuter && l.cosInner <= 1.0f))
    throw Error(what + ": a spot's cone angles must satisfy 0 <= inner <= outer, 0 < outer <= 90 degrees");
  punctualLights_.push_back(l);
  return uint32_t(punctualLights_.size() - 1);
}

Scene::Scene(const Scene& other) { *this = other; }

Scene& Scene::operator=(const Scene& other) {
  if (this == &other) return *this;
  vertices_ = other.vertices_;
  normals_ = other.normals_;
  faceNormals_ = other.faceNormals_;
  uvs_[0] = other.uvs_[0];
  uvs_[1] = other.uvs_[1];
  indices_ = other.indices_;
  materialIds_ = other.materialIds_;
  textureTexels_ = other.textureTexels_;
  textures_ = other.textures_;
  for (size_t i = 0; i < textures_.size(); ++i) textures_[i].texels = textureTexels_[i].data();
  materials_ = other.materials_;
  materialNames_ = other.materialNames_;
  effectGroupNames_ = other.effectGroupNames_;
  meshes_ = other.meshes_;
  lightTriangles_ = other.lightTriangles_;
  punctualLights_ = other.punctualLights_;
  sky_ = other.sky_;
  lightCdf_ = other.lightCdf_;
  skippedTriangles_ = other.skippedTriangles_;
  sceneRadius_ = other.sceneRadius_;
  sceneCenter_ = other.sceneCenter_;
  rig = other.rig;
  name = other.name;
  return *this;
}

Scene Scene::withoutColourTextures() const {
  Scene copy(*this);
  for (Material& m : copy.materials_) m.baseColorTexture = TextureRef();
  return copy;
}

bool Scene::hasAlphaTestedMaterial() const {
  return std::any_of(materials_.begin(), materials_.end(), [](const Material& m) { return m.alphaTested(); });
}

SceneView Scene::view() const {
  SceneView v;
  v.uvs[0] = uvs_[0].empty() ? nullptr : uvs_[0].data();
  v.uvs[1] = uvs_[1].empty() ? nullptr : uvs_[1].data();
  v.textures = textures_.empty() ? nullptr : textures_.data();
  v.textureCount = uint32_t(textures_.size());
  v.vertices = vertices_.data();
  v.normals = normals_.empty() ? nullptr : normals_.data();
  v.faceNormals = faceNormals_.empty() ? nullptr : faceNormals_.data();
  v.indices = indices_.data();
  v.materialIds = materialIds_.data();
  v.materials = materials_.data();
  v.triangleCount = triangleCount();
  v.lightTriangles = lightTriangles_.data();
  v.lightCdf = lightCdf_.data();
  v.triangleLightCount = uint32_t(lightTriangles_.size());
  v.punctualLights = punctualLights_.empty() ? nullptr : punctualLights_.data();
  v.punctualCount = uint32_t(punctualLights_.size());
  // Before finalize() the CDF holds the triangles only.
  const bool finalized = lightCdf_.size() == lightTriangles_.size() + 1 + punctualLights_.size() + (sky_.present() ? 1 : 0);
  v.lightCount = v.triangleLightCount + (finalized ? v.punctualCount + (sky_.present() ? 1 : 0) : 0);
  v.sky = sky_;
  v.sceneRadius = sceneRadius_;
  v.sceneCenter = sceneCenter_;
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
  for (const PunctualLight& l : punctualLights_) power += punctualPower(l, sceneRadius_);
  if (sky_.present()) power += sky_.power(sceneRadius_);
  return power;
}

bool effectLevelFromName(const std::string& name, EffectLevel& level) {
  for (int i = 0; i < kEffectLevels; ++i)
    if (name == effectLevelName(EffectLevel(i))) {
      level = EffectLevel(i);
      return true;
    }
  return false;
}

}  // namespace pvr
