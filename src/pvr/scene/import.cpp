// Mesh import through assimp. Material mapping (textures are not supported yet: the base colour
// factor alone is used):
//   glTF 2.0: baseColorFactor -> diffuse albedo; emissiveFactor -> Le; metallic >= 0.5 with
//             roughness <= 0.1 -> mirror (reflectance = base colour); KHR_materials_transmission
//             >= 0.5 -> glass (ior from KHR_materials_ior, default 1.5).
//   OBJ/MTL:  Kd -> albedo; Ke -> Le; illum 3 or 5 -> mirror (reflectance Ks, else Kd);
//             illum 4, 6, 7 or 9, or d < 0.5 -> glass (ior Ni).
#include <assimp/ObjMaterial.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <filesystem>

#include "pvr/scene/scene.h"
#include "pvr/util/error.h"

namespace pvr {
namespace {

Vec3 toVec3(const aiColor3D& c) { return {c.r, c.g, c.b}; }

Material convertMaterial(const aiMaterial& am) {
  Material m;
  aiColor3D color(0.8f, 0.8f, 0.8f);
  if (am.Get(AI_MATKEY_BASE_COLOR, color) != AI_SUCCESS) am.Get(AI_MATKEY_COLOR_DIFFUSE, color);
  m.albedo = toVec3(color);
  aiColor3D emissive(0, 0, 0);
  if (am.Get(AI_MATKEY_COLOR_EMISSIVE, emissive) == AI_SUCCESS) {
    float intensity = 1.0f;
    am.Get(AI_MATKEY_EMISSIVE_INTENSITY, intensity);
    m.emission = toVec3(emissive) * intensity;
  }
  float metallic = 0, roughness = 1, transmission = 0, opacity = 1, ior = 1.5f;
  int illum = -1;
  am.Get(AI_MATKEY_METALLIC_FACTOR, metallic);
  am.Get(AI_MATKEY_ROUGHNESS_FACTOR, roughness);
  am.Get(AI_MATKEY_TRANSMISSION_FACTOR, transmission);
  am.Get(AI_MATKEY_OPACITY, opacity);
  am.Get(AI_MATKEY_OBJ_ILLUM, illum);
  if (am.Get(AI_MATKEY_REFRACTI, ior) != AI_SUCCESS || !(ior >= 1.0f && ior < 10.0f)) ior = 1.5f;
  bool objGlass = illum == 4 || illum == 6 || illum == 7 || illum == 9;
  if (transmission >= 0.5f || objGlass || opacity < 0.5f) {
    m.type = MaterialType::Glass;
    m.ior = ior;
    aiColor3D tint(1, 1, 1);
    if (am.Get(AI_MATKEY_COLOR_TRANSPARENT, tint) == AI_SUCCESS && (tint.r + tint.g + tint.b) > 0) m.albedo = toVec3(tint);
    else m.albedo = {1, 1, 1};
  } else if ((metallic >= 0.5f && roughness <= 0.1f) || illum == 3 || illum == 5) {
    m.type = MaterialType::Mirror;
    aiColor3D specular(0, 0, 0);
    if ((illum == 3 || illum == 5) && am.Get(AI_MATKEY_COLOR_SPECULAR, specular) == AI_SUCCESS &&
        (specular.r + specular.g + specular.b) > 0)
      m.albedo = toVec3(specular);
  }
  for (int c = 0; c < 3; ++c) {  // energy conservation and sanity
    m.albedo[c] = std::clamp(std::isfinite(m.albedo[c]) ? m.albedo[c] : 0.0f, 0.0f, 1.0f);
    if (!std::isfinite(m.emission[c]) || m.emission[c] < 0) m.emission[c] = 0;
  }
  return m;
}

}  // namespace

void importMeshFile(const std::string& path, Scene& scene, const ImportOptions& options) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error("cannot open '" + path + "': no such file");
  if (fs::is_directory(path, ec)) throw Error("cannot open '" + path + "': it is a directory");
  Assimp::Importer importer;
  std::string ext = fs::path(path).extension().string();
  if (ext.empty() || !importer.IsExtensionSupported(ext))
    throw Error("unsupported scene format '" + (ext.empty() ? std::string("(no extension)") : ext) + "' for '" + path +
                "' (use .json, .gltf, .glb or .obj)");
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* as = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_PreTransformVertices |
                                                  aiProcess_JoinIdenticalVertices | aiProcess_SortByPType);
  if (!as) {
    std::string why = importer.GetErrorString();
    why.erase(std::remove(why.begin(), why.end(), '\n'), why.end());
    throw Error("cannot read '" + path + "': " + why);
  }
  if ((as->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !as->mRootNode)
    throw Error("cannot read '" + path + "': the file is incomplete");
  std::vector<uint32_t> materialMap(as->mNumMaterials);
  for (unsigned i = 0; i < as->mNumMaterials; ++i)
  {
    Material m = convertMaterial(*as->mMaterials[i]);
    m.emission *= options.emissionScale;
    materialMap[i] = scene.addMaterial(m, as->mMaterials[i]->GetName().C_Str());
  }
  if (as->mNumMaterials == 0) materialMap.push_back(scene.addMaterial(Material{}, "default"));
  for (unsigned mi = 0; mi < as->mNumMeshes; ++mi) {
    const aiMesh* mesh = as->mMeshes[mi];
    if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    std::vector<Vec3> vertices(mesh->mNumVertices), normals;
    for (unsigned v = 0; v < mesh->mNumVertices; ++v)
      vertices[v] = options.rotation.rotate(Vec3(mesh->mVertices[v].x, mesh->mVertices[v].y, mesh->mVertices[v].z) *
                                            options.scale) +
                    options.translation;
    if (mesh->HasNormals()) {
      normals.resize(mesh->mNumVertices);
      for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
        Vec3 n{mesh->mNormals[v].x, mesh->mNormals[v].y, mesh->mNormals[v].z};
        n = options.rotation.rotate(Vec3(n.x / options.scale.x, n.y / options.scale.y, n.z / options.scale.z));
        normals[v] = isFinite(n) && lengthSquared(n) > 0 ? normalize(n) : Vec3(0.0f);
      }
    }
    std::vector<uint32_t> indices;
    indices.reserve(mesh->mNumFaces * 3);
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      indices.insert(indices.end(), {face.mIndices[0], face.mIndices[1], face.mIndices[2]});
    }
    uint32_t material = mesh->mMaterialIndex < materialMap.size() ? materialMap[mesh->mMaterialIndex] : materialMap[0];
    std::string meshName = mesh->mName.length ? mesh->mName.C_Str() : fs::path(path).filename().string();
    scene.addMesh(meshName, vertices, normals, indices, material);
  }
}

}  // namespace pvr
