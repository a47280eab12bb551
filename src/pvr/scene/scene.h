#pragma once
// The host-side scene: indexed triangle meshes with per-triangle materials, the emitting
// triangles, and the headset rig. Loaders (built-in scenes, assimp import, JSON scene files)
// fill it; backends read it through SceneView.
#include <optional>
#include <string>
#include <vector>

#include "pvr/camera/stereo_rig.h"
#include "pvr/shading/scene_view.h"

namespace pvr {

struct MeshRange {
  std::string name;
  uint32_t firstTriangle = 0;
  uint32_t triangleCount = 0;
};

class Scene {
 public:
  Scene() = default;
  Scene(const Scene& other);  // textures' views point into the copy's own texels
  Scene& operator=(const Scene& other);
  Scene(Scene&&) noexcept = default;
  Scene& operator=(Scene&&) noexcept = default;
  // The same scene with every base-colour texture dropped (the constant colours stay; cut-outs
  // keep their masks): what textures cost, measured against it.
  Scene withoutColourTextures() const;

  uint32_t addMaterial(const Material& m, const std::string& name);
  // Adds a mesh; triangles with a non-finite vertex or (near) zero area are skipped and counted
  // in skippedTriangles(). `normals` is empty or one per vertex.
  void addMesh(const std::string& name, const std::vector<Vec3>& vertices, const std::vector<Vec3>& normals,
               const std::vector<uint32_t>& indices, uint32_t materialId);
  // The same with texture coordinates: `uvs[set]` empty or one per vertex (sets 0 and 1).
  void addMesh(const std::string& name, const std::vector<Vec3>& vertices, const std::vector<Vec3>& normals,
               const std::vector<Vec2> (&uvs)[2], const std::vector<uint32_t>& indices, uint32_t materialId);
  // A texture from its level-0 RGBA8 texels (row 0 at the top, byte 0 = R); the mip chain is built
  // here (box filter in linear light). Throws pvr::Error for a bad size. Returns its index for
  // TextureRef::texture.
  uint32_t addTexture(const std::string& name, int width, int height, std::vector<uint32_t> rgba, bool srgb,
                      WrapMode wrapS = WrapMode::Repeat, WrapMode wrapT = WrapMode::Repeat);
  uint32_t textureCount() const { return uint32_t(textures_.size()); }
  bool hasAlphaTestedMaterial() const;  ///< some material cuts texels out (intersectors test alpha)
  const std::vector<uint32_t>& textureTexels(uint32_t i) const { return textureTexels_[i]; }
  const std::vector<TextureView>& textureViews() const { return textures_; }  ///< texels point into this scene
  const std::vector<Vec2>& uvs(int set) const { return uvs_[set]; }
  const std::vector<uint32_t>& materialIds() const { return materialIds_; }
  // A point, spot or distant light (lights without area). Throws pvr::Error for non-finite or
  // negative values, a zero direction, or cones outside (0, 90] degrees with inner <= outer.
  uint32_t addPunctualLight(const PunctualLight& light, const std::string& name);
  const std::vector<PunctualLight>& punctualLights() const { return punctualLights_; }
  // A uniform sky over the upper hemisphere. Throws pvr::Error for negative or non-finite values.
  void setSky(const SkyLight& sky);
  const SkyLight& sky() const { return sky_; }
  // Builds the light list; throws pvr::Error if nothing emits light or the scene is empty.
  void finalize();

  SceneView view() const;
  Bounds3 bounds() const;
  uint32_t triangleCount() const { return uint32_t(materialIds_.size()); }
  uint32_t lightTriangleCount() const { return uint32_t(lightTriangles_.size()); }
  uint64_t skippedTriangles() const { return skippedTriangles_; }
  const std::vector<MeshRange>& meshes() const { return meshes_; }
  const std::vector<Material>& materials() const { return materials_; }
  void setEffect(uint32_t material, EffectLevel level) { materials_.at(material).effect = level; }
  // Effect groups: names by index, "rest" (group 0, every material not put in another) first.
  // addEffectGroup throws pvr::Error past kMaxEffectGroups or for a name already taken.
  uint32_t addEffectGroup(const std::string& name);
  void setEffectGroup(uint32_t material, uint32_t group);  ///< throws pvr::Error for an unknown group
  const std::vector<std::string>& effectGroupNames() const { return effectGroupNames_; }
  int effectGroupIndex(const std::string& name) const;  ///< -1: no such group
  int materialIndex(const std::string& name) const;     ///< the first material of that name, -1: none
  const std::vector<std::string>& materialNames() const { return materialNames_; }
  // Index of the mesh that holds a triangle, or -1.
  int meshOfTriangle(uint32_t prim) const;
  // Total emitted power (W) per channel: sum of Le * pi * area over front faces.
  Vec3 totalLightPower() const;

  const std::vector<Vec3>& vertices() const { return vertices_; }
  const std::vector<uint32_t>& indices() const { return indices_; }
  const std::vector<Vec3>& faceNormals() const { return faceNormals_; }

  StereoRig rig = defaultRig();
  std::string name;

 private:
  std::vector<Vec3> vertices_;
  std::vector<Vec3> normals_;  // empty if no mesh has normals
  std::vector<Vec3> faceNormals_;  // one per triangle, by winding (finalize)
  std::vector<Vec2> uvs_[2];     // empty if no mesh has that set
  std::vector<uint32_t> indices_;
  std::vector<uint32_t> materialIds_;
  std::vector<std::vector<uint32_t>> textureTexels_;
  std::vector<TextureView> textures_;
  std::vector<Material> materials_;
  std::vector<std::string> materialNames_;
  std::vector<std::string> effectGroupNames_{"rest"};
  std::vector<MeshRange> meshes_;
  std::vector<uint32_t> lightTriangles_;
  std::vector<PunctualLight> punctualLights_;
  SkyLight sky_;
  std::vector<float> lightCdf_;
  uint64_t skippedTriangles_ = 0;
  float sceneRadius_ = 1.0f;
  Vec3 sceneCenter_{0, 0, 0};
};

// Built-in scenes by name ("cornell", "cornell-caustics"); throws pvr::Error for an unknown name.
Scene builtinScene(const std::string& name);
std::vector<std::string> builtinSceneNames();

// Where an imported mesh goes: scale, then rotate, then translate.
struct ImportOptions {
  Vec3 scale{1, 1, 1};
  Quat rotation;
  Vec3 translation{0, 0, 0};
  float emissionScale = 1.0f;  ///< glTF's emissiveFactor is at most 1: scale it to a light's Le
  bool importLights = true;    ///< the file's point, spot and directional lights (KHR_lights_punctual)
};

// The camera a mesh file carries: a glTF file's first perspective camera in its scene's node
// tree, read from the glTF JSON (its node's world transform, then the import's). Only the pose: a
// headset keeps its own field of view. Other formats' cameras are not read: Debian's assimp 5.2
// counts a 3DS camera's node transform twice, and Dabrovic Sponza's camera lives only in its
// keyframer tracks, which assimp does not apply (both come out at the wrong place).
struct FileCamera {
  std::string name;
  Pose pose;
};

// A mesh file through assimp (.gltf, .glb, .obj with .mtl, and whatever else assimp reads).
// Appends to `scene`; returns the file's camera, if any; throws pvr::Error for a missing,
// unsupported or malformed file.
std::optional<FileCamera> importMeshFile(const std::string& path, Scene& scene, const ImportOptions& options = {});

// A JSON scene file (see docs/scene-format.md) or, for any other extension, a mesh file.
// The result is finalized. Throws pvr::Error with one line naming the problem.
Scene loadScene(const std::string& pathOrBuiltin);

// "raster" | "shadows" | "reflections" | "gi" | "path"; false for anything else.
bool effectLevelFromName(const std::string& name, EffectLevel& level);

}  // namespace pvr
