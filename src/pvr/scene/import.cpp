// Mesh import through assimp. Material mapping:
//   glTF 2.0: the microfacet material (shading/bsdf.h): baseColorFactor x baseColorTexture,
//             metallicFactor and roughnessFactor x metallicRoughnessTexture (B, G),
//             KHR_materials_transmission and KHR_materials_ior, emissiveFactor x emissiveTexture
//             -> Le, occlusionTexture; exactly smooth metal (metallic 1, roughness 0, no texture)
//             -> mirror, exactly smooth full transmission -> glass; alphaMode MASK / BLEND with
//             alphaCutoff -> alpha-tested cut-outs.
//   OBJ/MTL:  Kd (x map_Kd) -> albedo; Ke -> Le; illum 3 or 5 -> mirror (reflectance Ks, else Kd);
//             illum 4, 6, 7 or 9, or d < 0.5 without map_d -> glass (ior Ni); map_d -> cut-out;
//             Ks (x map_Ks) with illum 2 (or none) -> a glossy dielectric layer of F0 = 0.08 max(Ks)
//             (Ks read as Blender's "specular": 0.5 is a plastic's 0.04)
//             and roughness from Ns (x map_Ns), alpha = sqrt(2 / (Ns + 2)) (Blinn-Phong's match).
//   3DS:      diffuse colour (x its texture map) -> albedo; specular colour and shininess as
//             OBJ's Ks and Ns.
// Texture coordinates are taken with assimp's FlipUVs, so v runs down the image as the texels do.
#include <assimp/GltfMaterial.h>
#include <assimp/ObjMaterial.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cctype>
#include <cstring>
#include <fstream>
#include <optional>
#include <nlohmann/json.hpp>
#include <assimp/Importer.hpp>
#include <filesystem>

#include "pvr/scene/scene.h"
#include "pvr/scene/texture_file.h"
#include "pvr/util/error.h"
#include "pvr/util/json_number.h"

namespace pvr {
namespace {

Vec3 toVec3(const aiColor3D& c) { return {c.r, c.g, c.b}; }

WrapMode wrapOf(aiTextureMapMode mode) {
  switch (mode) {
    case aiTextureMapMode_Clamp:
    case aiTextureMapMode_Decal: return WrapMode::ClampToEdge;
    case aiTextureMapMode_Mirror: return WrapMode::MirroredRepeat;
    default: return WrapMode::Repeat;
  }
}

// The material's texture of one kind: an embedded image ("*N" or a .glb's own), or a file next to
// the model. None (texture -1) when there is no such texture or it cannot be read.
TextureRef textureOf(const aiScene& as, const aiMaterial& am, aiTextureType type, bool srgb, const std::string& folder,
                     TextureLoader& loader) {
  TextureRef ref;
  aiString file;
  aiTextureMapMode modes[2] = {aiTextureMapMode_Wrap, aiTextureMapMode_Wrap};
  unsigned uvIndex = 0;
  if (am.GetTextureCount(type) == 0 || am.GetTexture(type, 0, &file, nullptr, &uvIndex, nullptr, nullptr, modes) != AI_SUCCESS)
    return ref;
  int source = 0;
  if (am.Get(AI_MATKEY_UVWSRC(type, 0), source) == AI_SUCCESS) uvIndex = unsigned(source);
  ref.texCoord = uvIndex > 1 ? 0u : uvIndex;
  WrapMode s = wrapOf(modes[0]), t = wrapOf(modes[1]);
  if (const aiTexture* embedded = as.GetEmbeddedTexture(file.C_Str())) {
    std::string key = std::string("embedded ") + file.C_Str();
    if (embedded->mHeight == 0)
      ref.texture = loader.fromMemory(key, reinterpret_cast<const unsigned char*>(embedded->pcData), embedded->mWidth, srgb, s, t);
    else
      ref.texture = loader.fromBgra(key, reinterpret_cast<const unsigned char*>(embedded->pcData), int(embedded->mWidth),
                                    int(embedded->mHeight), srgb, s, t);
  } else {
    std::string name = file.C_Str();
    std::replace(name.begin(), name.end(), '\\', '/');
    ref.texture = loader.fromFile((std::filesystem::path(folder) / name).string(), srgb, s, t);
  }
  return ref;
}

// glTF's metallic-roughness material; exactly smooth metal or glass without textures become the
// delta materials, which need no sampling.
void microfacetFromGltf(const aiScene& as, const aiMaterial& am, float metallic, float roughness, float transmission,
                        float ior, const std::string& folder, TextureLoader& textures, Material& m) {
  auto unit = [](float x, float fallback) { return std::isfinite(x) ? std::clamp(x, 0.0f, 1.0f) : fallback; };
  m.metallic = unit(metallic, 0.0f);
  m.roughness = unit(roughness, 1.0f);
  m.transmission = unit(transmission, 0.0f);
  m.ior = ior;
  float f = (ior - 1.0f) / (ior + 1.0f);
  m.specularF0 = f * f;
  // assimp 5.2 files glTF's metallicRoughnessTexture as UNKNOWN and occlusionTexture as LIGHTMAP.
  m.metallicRoughnessTexture = textureOf(as, am, aiTextureType_UNKNOWN, false, folder, textures);
  m.emissiveTexture = textureOf(as, am, aiTextureType_EMISSIVE, true, folder, textures);
  m.occlusionTexture = textureOf(as, am, aiTextureType_LIGHTMAP, false, folder, textures);
  if (m.occlusionTexture.present()) {
    float strength = 1.0f;
    if (am.Get(AI_MATKEY_GLTF_TEXTURE_STRENGTH(aiTextureType_LIGHTMAP, 0), strength) == AI_SUCCESS && std::isfinite(strength))
      m.occlusionStrength = std::clamp(strength, 0.0f, 1.0f);
  }
  m.type = MaterialType::Microfacet;
  if (m.roughness == 0.0f && !m.metallicRoughnessTexture.present()) {
    if (m.metallic == 1.0f) m.type = MaterialType::Mirror;
    else if (m.metallic == 0.0f && m.transmission == 1.0f) m.type = MaterialType::Glass;
  }
}

// OBJ/MTL and 3DS: a Phong specular colour and exponent become a glossy dielectric layer.
void glossyLayerFromPhong(const aiScene& as, const aiMaterial& am, int illum, const std::string& folder,
                          TextureLoader& textures, Material& m) {
  aiColor3D ks(0, 0, 0);
  float shininess = 0.0f;
  am.Get(AI_MATKEY_COLOR_SPECULAR, ks);
  am.Get(AI_MATKEY_SHININESS, shininess);
  float f0 = std::max({ks.r, ks.g, ks.b});
  if (illum == 0 || illum == 1 || !std::isfinite(f0) || !(f0 > 0.0f)) return;  // no highlights
  if (!std::isfinite(shininess) || shininess < 0.0f) shininess = 0.0f;
  m.type = MaterialType::Microfacet;
  m.specularF0 = 0.08f * std::min(f0, 1.0f);  // Ks as Blender's "specular" (0.5: F0 = 0.04, plastic)
  m.roughness = std::sqrt(std::sqrt(2.0f / (shininess + 2.0f)));  // alpha = roughness^2
  m.specularTexture = textureOf(as, am, aiTextureType_SPECULAR, false, folder, textures);
  m.shininessTexture = textureOf(as, am, aiTextureType_SHININESS, false, folder, textures);
  m.shininess = shininess;
}

Material convertMaterial(const aiScene& as, const aiMaterial& am, const std::string& folder, TextureLoader& textures) {
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
  m.baseColorTexture = textureOf(as, am, aiTextureType_BASE_COLOR, true, folder, textures);
  if (!m.baseColorTexture.present()) m.baseColorTexture = textureOf(as, am, aiTextureType_DIFFUSE, true, folder, textures);
  m.opacityTexture = textureOf(as, am, aiTextureType_OPACITY, false, folder, textures);
  m.normalTexture = textureOf(as, am, aiTextureType_NORMALS, false, folder, textures);
  if (m.normalTexture.present()) {
    float scale = 1.0f;
    if (am.Get(AI_MATKEY_GLTF_TEXTURE_SCALE(aiTextureType_NORMALS, 0), scale) == AI_SUCCESS && std::isfinite(scale)) m.normalScale = scale;
  } else {  // a bump (height) map (OBJ map_bump, 3DS bump): its slopes become a normal map
    TextureRef bump = textureOf(as, am, aiTextureType_HEIGHT, false, folder, textures);
    if (bump.present()) {
      bump.texture = textures.normalsFromHeight(bump.texture, 4.0f);
      m.normalTexture = bump;
    }
  }
  aiString alphaMode;
  const bool gltf = am.Get(AI_MATKEY_GLTF_ALPHAMODE, alphaMode) == AI_SUCCESS;
  if (gltf) {
    std::string mode = alphaMode.C_Str();
    m.alphaMode = mode == "MASK" ? AlphaMode::Mask : mode == "BLEND" ? AlphaMode::Blend : AlphaMode::Opaque;
    am.Get(AI_MATKEY_GLTF_ALPHACUTOFF, m.alphaCutoff);
    aiColor4D base(1, 1, 1, 1);
    if (am.Get(AI_MATKEY_BASE_COLOR, base) == AI_SUCCESS && std::isfinite(base.a)) m.alpha = std::clamp(base.a, 0.0f, 1.0f);
  } else if (m.opacityTexture.present()) {  // OBJ map_d: a cut-out, not glass
    m.alphaMode = AlphaMode::Mask;
    m.alpha = std::isfinite(opacity) ? std::clamp(opacity, 0.0f, 1.0f) : 1.0f;
  }
  if (!(m.alphaCutoff >= 0.0f && m.alphaCutoff <= 1.0f)) m.alphaCutoff = 0.5f;
  if (!gltf && (objGlass || (opacity < 0.5f && !m.opacityTexture.present()))) {
    m.type = MaterialType::Glass;
    m.ior = ior;
    aiColor3D tint(1, 1, 1);
    if (am.Get(AI_MATKEY_COLOR_TRANSPARENT, tint) == AI_SUCCESS && (tint.r + tint.g + tint.b) > 0) m.albedo = toVec3(tint);
    else m.albedo = {1, 1, 1};
  } else if (illum == 3 || illum == 5) {
    m.type = MaterialType::Mirror;
    aiColor3D specular(0, 0, 0);
    if (am.Get(AI_MATKEY_COLOR_SPECULAR, specular) == AI_SUCCESS && (specular.r + specular.g + specular.b) > 0)
      m.albedo = toVec3(specular);
  } else if (!gltf) {
    glossyLayerFromPhong(as, am, illum, folder, textures, m);
  }
  if (gltf) microfacetFromGltf(as, am, metallic, roughness, transmission, ior, folder, textures, m);
  for (int c = 0; c < 3; ++c) {  // energy conservation and sanity
    m.albedo[c] = std::clamp(std::isfinite(m.albedo[c]) ? m.albedo[c] : 0.0f, 0.0f, 1.0f);
    if (!std::isfinite(m.emission[c]) || m.emission[c] < 0) m.emission[c] = 0;
  }
  return m;
}

// What assimp 5.2 drops of a glTF file's materials, read from its JSON: KHR_texture_transform on
// each texture (base colour, metallic-roughness, normal, emissive, occlusion) and
// KHR_materials_emissive_strength. Empty for other formats, or when the JSON cannot be read
// (assimp then reports the problem itself).
struct TextureTransform {
  bool present = false;
  TextureRef transform;  ///< offset, scale, rotation, and texCoord if the extension overrides it
  bool texCoordOverride = false;
  void applyTo(TextureRef& ref) const {
    if (!present || !ref.present()) return;
    ref.offset = transform.offset;
    ref.scale = transform.scale;
    ref.rotation = transform.rotation;
    if (texCoordOverride) ref.texCoord = transform.texCoord > 1 ? 0u : transform.texCoord;
  }
};
enum GltfTextureSlot { kBaseColorSlot, kMetallicRoughnessSlot, kNormalSlot, kEmissiveSlot, kOcclusionSlot, kSlots };
struct GltfExtras {
  TextureTransform transforms[kSlots];
  float emissiveStrength = 1.0f;
  std::string name;
};

TextureTransform transformOf(const nlohmann::json& textureInfo) {
  TextureTransform out;
  if (!textureInfo.is_object() || !textureInfo.contains("extensions") ||
      !textureInfo["extensions"].contains("KHR_texture_transform"))
    return out;
  const nlohmann::json& x = textureInfo["extensions"]["KHR_texture_transform"];
  out.present = true;
  if (x.contains("offset") && x["offset"].size() == 2) out.transform.offset = {jsonNumber<float>(x["offset"][0], "offset"), jsonNumber<float>(x["offset"][1], "offset")};
  if (x.contains("scale") && x["scale"].size() == 2) out.transform.scale = {jsonNumber<float>(x["scale"][0], "scale"), jsonNumber<float>(x["scale"][1], "scale")};
  if (x.contains("rotation")) out.transform.rotation = jsonNumber<float>(x["rotation"], "rotation");
  if (x.contains("texCoord")) out.transform.texCoord = jsonNumber<uint32_t>(x["texCoord"], "texCoord"), out.texCoordOverride = true;
  return out;
}

std::vector<GltfExtras> readGltfExtras(const nlohmann::json& doc) {
  using nlohmann::json;
  std::vector<GltfExtras> out;
  try {
    if (!doc.is_object() || !doc.contains("materials") || !doc["materials"].is_array()) return out;
    for (const json& m : doc["materials"]) {
      GltfExtras e;
      if (!m.is_object()) {
        out.push_back(e);
        continue;
      }
      if (m.contains("name") && m["name"].is_string()) e.name = m["name"].get<std::string>();
      try {
        const json* strength = nullptr;
        if (m.contains("extensions") && m["extensions"].contains("KHR_materials_emissive_strength"))
          strength = &m["extensions"]["KHR_materials_emissive_strength"];
        if (strength && strength->contains("emissiveStrength") && (*strength)["emissiveStrength"].is_number())
          e.emissiveStrength = jsonNumber<float>((*strength)["emissiveStrength"], "emissiveStrength");
        if (m.contains("pbrMetallicRoughness") && m["pbrMetallicRoughness"].is_object()) {
          const json& pbr = m["pbrMetallicRoughness"];
          if (pbr.contains("baseColorTexture")) e.transforms[kBaseColorSlot] = transformOf(pbr["baseColorTexture"]);
          if (pbr.contains("metallicRoughnessTexture"))
            e.transforms[kMetallicRoughnessSlot] = transformOf(pbr["metallicRoughnessTexture"]);
        }
        if (m.contains("normalTexture")) e.transforms[kNormalSlot] = transformOf(m["normalTexture"]);
        if (m.contains("emissiveTexture")) e.transforms[kEmissiveSlot] = transformOf(m["emissiveTexture"]);
        if (m.contains("occlusionTexture")) e.transforms[kOcclusionSlot] = transformOf(m["occlusionTexture"]);
      } catch (const std::exception&) {  // a value out of spec: this material's extensions are dropped, not the file's
        GltfExtras plain;
        plain.name = e.name;
        e = plain;
      }
      out.push_back(e);
    }
  } catch (const std::exception&) {
    out.clear();
  }
  return out;
}

// Bytes a glTF accessor element takes: component size times component count.
size_t gltfElementBytes(const nlohmann::json& accessor) {
  static const std::pair<int, size_t> kComponents[] = {{5120, 1}, {5121, 1}, {5122, 2}, {5123, 2}, {5125, 4}, {5126, 4}};
  static const std::pair<const char*, size_t> kTypes[] = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
                                                          {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};
  if (!accessor.is_object()) return 0;
  const nlohmann::json& c = accessor.contains("componentType") ? accessor["componentType"] : nlohmann::json();
  const nlohmann::json& t = accessor.contains("type") ? accessor["type"] : nlohmann::json();
  const int componentType = jsonNumberFits<int>(c) ? c.get<int>() : 0;
  const std::string type = t.is_string() ? t.get<std::string>() : std::string();
  size_t component = 0, count = 0;
  for (auto [code, bytes] : kComponents)
    if (componentType == code) component = bytes;
  for (auto [name, n] : kTypes)
    if (type == name) count = n;
  return component * count;
}

// A .gltf's or .glb's JSON, parsed once for the range check and the extras (discarded when it
// does not parse: assimp reports that itself), and the bytes of a GLB's BIN chunk.
struct GltfFile {
  nlohmann::json doc;
  bool glb = false;
  uint64_t binBytes = 0;
};

std::optional<GltfFile> readGltfFile(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext != ".gltf" && ext != ".glb") return std::nullopt;
  GltfFile file;
  file.glb = ext == ".glb";
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  std::string text;
  if (file.glb) {  // header (12 bytes), then the JSON chunk (length, "JSON", bytes), then BIN
    auto malformed = [&](const std::string& why) { throw Error("malformed glTF '" + path + "': " + why); };
    auto u32 = [&](size_t at) {
      uint32_t v;
      std::memcpy(&v, bytes.data() + at, 4);
      return v;
    };
    if (bytes.size() < 20 || bytes.compare(0, 4, "glTF") != 0 || bytes.compare(16, 4, "JSON") != 0)
      malformed("no GLB header and JSON chunk");
    const uint64_t jsonLength = u32(12);
    if (20 + jsonLength > bytes.size()) malformed("the JSON chunk runs past the end of the file");
    text = bytes.substr(20, jsonLength);
    const uint64_t bin = 20 + ((jsonLength + 3) & ~uint64_t(3));
    if (bin + 8 <= bytes.size() && bytes.compare(bin + 4, 4, std::string("BIN\0", 4)) == 0) {
      file.binBytes = u32(bin);
      if (bin + 8 + file.binBytes > bytes.size()) malformed("the BIN chunk runs past the end of the file");
    }
  } else {
    text = std::move(bytes);
  }
  // assimp's parser lets invalid UTF-8 through and then misreads what follows (a fuzzer finding):
  // JSON that is not valid is refused here.
  try {
    file.doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw Error("malformed glTF '" + path + "': not valid JSON (at byte " + std::to_string(e.byte) + ")");
  }
  return file;
}

// Debian's assimp 5.2 reads past a buffer when a glTF's accessors or buffer views claim more bytes
// than the file holds (a heap overflow found by scripts/fuzz.sh). Such a file breaks the glTF
// spec, so it is refused here, before assimp sees it, with the element at fault named.
void checkGltfRanges(const GltfFile& file, const std::string& path) {
  using nlohmann::json;
  const json& doc = file.doc;
  if (!doc.is_object()) return;  // assimp reports a glTF that is not an object
  auto malformed = [&](const std::string& why) { throw Error("malformed glTF '" + path + "': " + why); };
  auto array = [&](const char* key) { return doc.contains(key) && doc[key].is_array() ? doc[key] : json::array(); };
  auto number = [](const json& o, const char* key, uint64_t fallback) {
    return o.contains(key) && o[key].is_number_unsigned() ? o[key].get<uint64_t>() : fallback;
  };
  const json buffers = array("buffers"), views = array("bufferViews"), accessors = array("accessors");
  std::vector<uint64_t> held(buffers.size(), 0);  // bytes each buffer really has
  for (size_t b = 0; b < buffers.size(); ++b) {
    const json& buffer = buffers[b];
    if (!buffer.is_object()) malformed("buffer " + std::to_string(b) + " is not an object");
    const uint64_t claimed = number(buffer, "byteLength", 0);
    uint64_t have = claimed;
    if (!buffer.contains("uri")) {
      have = file.glb && b == 0 ? file.binBytes : 0;
    } else if (buffer["uri"].is_string()) {
      const std::string uri = buffer["uri"].get<std::string>();
      if (uri.rfind("data:", 0) == 0) {
        const size_t comma = uri.find(',');
        have = comma == std::string::npos ? 0 : (uri.size() - comma - 1) / 4 * 3;
      } else {
        std::error_code ec;
        const auto size = std::filesystem::file_size(std::filesystem::path(path).parent_path() / uri, ec);
        if (!ec) have = size;  // a missing file is assimp's to report
      }
    }
    if (claimed > have)
      malformed("buffer " + std::to_string(b) + " claims " + std::to_string(claimed) + " bytes, " +
                std::to_string(have) + " are there");
    held[b] = claimed;
  }
  std::vector<uint64_t> viewBytes(views.size(), 0);
  for (size_t v = 0; v < views.size(); ++v) {
    const json& view = views[v];
    if (!view.is_object()) malformed("bufferView " + std::to_string(v) + " is not an object");
    const uint64_t buffer = number(view, "buffer", ~uint64_t(0));
    if (buffer >= held.size()) malformed("bufferView " + std::to_string(v) + " names no buffer");
    const uint64_t offset = number(view, "byteOffset", 0), length = number(view, "byteLength", 0);
    if (offset > held[buffer] || length > held[buffer] - offset)
      malformed("bufferView " + std::to_string(v) + " runs past the end of buffer " + std::to_string(buffer));
    viewBytes[v] = length;
  }
  for (size_t a = 0; a < accessors.size(); ++a) {
    const json& accessor = accessors[a];
    if (!accessor.is_object() || !accessor.contains("bufferView")) continue;  // sparse or all zeros
    const uint64_t view = number(accessor, "bufferView", ~uint64_t(0));
    if (view >= viewBytes.size()) malformed("accessor " + std::to_string(a) + " names no bufferView");
    const uint64_t element = gltfElementBytes(accessor), count = number(accessor, "count", 0);
    if (element == 0) malformed("accessor " + std::to_string(a) + " has an unknown componentType or type");
    if (count == 0) continue;
    const uint64_t stride = std::max<uint64_t>(number(views[view], "byteStride", 0), element);
    const uint64_t offset = number(accessor, "byteOffset", 0);
    if (count > viewBytes[view] / stride + 1 || offset > viewBytes[view] ||
        (count - 1) * stride + element > viewBytes[view] - offset)
      malformed("accessor " + std::to_string(a) + " reads past the end of bufferView " + std::to_string(view));
  }
  // assimp 5.2 takes an embedded image's format from the part of its mimeType after '/', and reads
  // address 1 when there is no '/' (a fuzzer finding). Every glTF image type has one.
  const json images = array("images");
  for (size_t i = 0; i < images.size(); ++i) {
    if (!images[i].is_object() || !images[i].contains("mimeType")) continue;
    const json& mime = images[i]["mimeType"];
    if (!mime.is_string() || mime.get<std::string>().find('/') == std::string::npos)
      malformed("image " + std::to_string(i) + " has a mimeType that is not a MIME type (image/png, image/jpeg)");
  }
  // assimp 5.2 sizes a primitive without positions from a vertex count of zero, and a strip or
  // fan then asks for ~64 GB. The spec lets viewers skip such primitives; we refuse the file.
  const json meshes = array("meshes");
  for (size_t m = 0; m < meshes.size(); ++m) {
    if (!meshes[m].is_object() || !meshes[m].contains("primitives") || !meshes[m]["primitives"].is_array()) continue;
    const json& primitives = meshes[m]["primitives"];
    for (size_t p = 0; p < primitives.size(); ++p) {
      const json& primitive = primitives[p];
      if (!primitive.is_object() || !primitive.contains("attributes") || !primitive["attributes"].is_object() ||
          !primitive["attributes"].contains("POSITION"))
        malformed("mesh " + std::to_string(m) + " primitive " + std::to_string(p) + " has no POSITION attribute");
    }
  }
}

// A glTF node's local transform, column-major: its "matrix", or translation * rotation * scale.
// False when malformed.
using Matrix4 = std::array<double, 16>;
Matrix4 multiply(const Matrix4& a, const Matrix4& b) {
  Matrix4 m{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      for (int k = 0; k < 4; ++k) m[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
  return m;
}
bool gltfNodeMatrix(const nlohmann::json& node, Matrix4& m) {
  auto numbers = [&](const char* key, size_t count, std::array<double, 16>& out) {
    if (!node.contains(key)) return true;
    const nlohmann::json& a = node[key];
    if (!a.is_array() || a.size() != count) return false;
    for (size_t i = 0; i < count; ++i) {
      if (!a[i].is_number()) return false;
      out[i] = a[i].get<double>();
    }
    return true;
  };
  m = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  if (node.contains("matrix")) return numbers("matrix", 16, m);
  std::array<double, 16> t{0, 0, 0}, r{0, 0, 0, 1}, sc{1, 1, 1};
  if (!numbers("translation", 3, t) || !numbers("rotation", 4, r) || !numbers("scale", 3, sc)) return false;
  const double len = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
  if (!(len > 0.0)) return false;
  const double x = r[0] / len, y = r[1] / len, z = r[2] / len, w = r[3] / len;
  const double rot[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),   // column 0
                         2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),   // column 1
                         2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y)};
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row) m[c * 4 + row] = rot[c * 3 + row] * sc[c];
  m[12] = t[0], m[13] = t[1], m[14] = t[2];
  return true;
}

// The first perspective camera met walking the glTF's scene (its "scene", else the first) depth
// first: glTF's camera sits at its node's origin looking down -Z with +Y up. The file's node tree
// is read here because assimp moves a camera node's translation into the camera as well.
std::optional<FileCamera> gltfCamera(const nlohmann::json& doc) {
  using nlohmann::json;
  if (!doc.is_object() || !doc.contains("nodes") || !doc["nodes"].is_array() || !doc.contains("scenes") ||
      !doc["scenes"].is_array() || !doc.contains("cameras") || !doc["cameras"].is_array())
    return std::nullopt;
  const json &nodes = doc["nodes"], &cameras = doc["cameras"], &scenes = doc["scenes"];
  const size_t sceneIndex = doc.contains("scene") && doc["scene"].is_number_unsigned() ? doc["scene"].get<size_t>() : 0;
  if (sceneIndex >= scenes.size() || !scenes[sceneIndex].is_object() || !scenes[sceneIndex].contains("nodes") ||
      !scenes[sceneIndex]["nodes"].is_array())
    return std::nullopt;
  std::vector<bool> visited(nodes.size(), false);  // a node in two places (or a cycle) is walked once
  std::optional<FileCamera> found;
  auto walk = [&](auto&& self, const json& index, const Matrix4& parent) -> void {
    if (found || !index.is_number_unsigned() || index.get<size_t>() >= nodes.size()) return;
    const size_t i = index.get<size_t>();
    if (visited[i] || !nodes[i].is_object()) return;
    visited[i] = true;
    const json& node = nodes[i];
    Matrix4 local;
    if (!gltfNodeMatrix(node, local)) return;
    const Matrix4 world = multiply(parent, local);
    if (node.contains("camera") && node["camera"].is_number_unsigned() && node["camera"].get<size_t>() < cameras.size()) {
      const json& camera = cameras[node["camera"].get<size_t>()];
      if (camera.is_object() && camera.contains("type") && camera["type"].is_string() &&
          camera["type"].get<std::string>() == "perspective") {
        const Vec3 position{float(world[12]), float(world[13]), float(world[14])};
        const Vec3 forward{float(-world[8]), float(-world[9]), float(-world[10])}, up{float(world[4]), float(world[5]), float(world[6])};
        const float forwardLength = length(forward), upLength = length(up);  // a node's scale may be tiny (mm to m)
        if (isFinite(position) && forwardLength > 0.0f && upLength > 0.0f && std::isfinite(forwardLength) &&
            std::isfinite(upLength) && lengthSquared(cross(forward / forwardLength, up / upLength)) > 1e-6f) {
          FileCamera c;
          c.name = camera.contains("name") && camera["name"].is_string()   ? camera["name"].get<std::string>()
                   : node.contains("name") && node["name"].is_string() ? node["name"].get<std::string>()
                                                                         : "camera " + std::to_string(node["camera"].get<size_t>());
          c.pose.position = position;
          c.pose.orientation = lookAtOrientation(position, position + normalize(forward), normalize(up));
          found = c;
          return;
        }
      }
    }
    if (node.contains("children") && node["children"].is_array())
      for (const json& child : node["children"]) self(self, child, world);
  };
  const Matrix4 identity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  for (const json& root : scenes[sceneIndex]["nodes"]) walk(walk, root, identity);
  return found;
}

}  // namespace

std::optional<FileCamera> importMeshFile(const std::string& path, Scene& scene, const ImportOptions& options) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error("cannot open '" + path + "': no such file");
  if (fs::is_directory(path, ec)) throw Error("cannot open '" + path + "': it is a directory");
  Assimp::Importer importer;
  std::string ext = fs::path(path).extension().string();
  if (ext.empty() || !importer.IsExtensionSupported(ext))
    throw Error("unsupported scene format '" + (ext.empty() ? std::string("(no extension)") : ext) + "' for '" + path +
                "' (use .json, .gltf, .glb or .obj)");
  const std::optional<GltfFile> gltf = readGltfFile(path);
  if (gltf) checkGltfRanges(*gltf, path);
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* as = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_PreTransformVertices |
                                                  aiProcess_JoinIdenticalVertices | aiProcess_SortByPType |
                                                  aiProcess_FlipUVs);
  if (!as) {
    std::string why = importer.GetErrorString();
    why.erase(std::remove(why.begin(), why.end(), '\n'), why.end());
    throw Error("cannot read '" + path + "': " + why);
  }
  if ((as->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !as->mRootNode)
    throw Error("cannot read '" + path + "': the file is incomplete");
  std::vector<uint32_t> materialMap(as->mNumMaterials);
  TextureLoader textures(scene);
  const std::vector<GltfExtras> gltfExtras = gltf ? readGltfExtras(gltf->doc) : std::vector<GltfExtras>();
  const std::string folder = fs::path(path).parent_path().string();
  for (unsigned i = 0; i < as->mNumMaterials; ++i)
  {
    Material m = convertMaterial(*as, *as->mMaterials[i], folder, textures);
    // assimp reorders the file's materials: find this one by its (unique) name, or by index when
    // the file names none.
    const GltfExtras* found = nullptr;
    const std::string materialName = as->mMaterials[i]->GetName().C_Str();
    int sameName = 0;
    for (const GltfExtras& e : gltfExtras)
      if (!materialName.empty() && e.name == materialName) found = &e, ++sameName;
    if (sameName > 1) found = nullptr;
    bool anyNamed = std::any_of(gltfExtras.begin(), gltfExtras.end(), [](const GltfExtras& e) { return !e.name.empty(); });
    if (!found && !anyNamed && i < gltfExtras.size()) found = &gltfExtras[i];
    if (found) {
      const GltfExtras& e = *found;
      e.transforms[kBaseColorSlot].applyTo(m.baseColorTexture);
      e.transforms[kMetallicRoughnessSlot].applyTo(m.metallicRoughnessTexture);
      e.transforms[kNormalSlot].applyTo(m.normalTexture);
      e.transforms[kEmissiveSlot].applyTo(m.emissiveTexture);
      e.transforms[kOcclusionSlot].applyTo(m.occlusionTexture);
      if (std::isfinite(e.emissiveStrength) && e.emissiveStrength >= 0.0f) m.emission *= e.emissiveStrength;
    }
    m.emission *= options.emissionScale;
    materialMap[i] = scene.addMaterial(m, as->mMaterials[i]->GetName().C_Str());
  }
  if (as->mNumMaterials == 0) materialMap.push_back(scene.addMaterial(Material{}, "default"));
  if (options.importLights)
    for (unsigned li = 0; li < as->mNumLights; ++li) {
      const aiLight& al = *as->mLights[li];
      PunctualLight l;
      if (al.mType == aiLightSource_POINT) l.kind = PunctualKind::Point;
      else if (al.mType == aiLightSource_SPOT) l.kind = PunctualKind::Spot;
      else if (al.mType == aiLightSource_DIRECTIONAL) l.kind = PunctualKind::Directional;
      else continue;  // ambient and area lights of other formats: not imported
      l.position = options.rotation.rotate(Vec3(al.mPosition.x, al.mPosition.y, al.mPosition.z) * options.scale) + options.translation;
      Vec3 d = options.rotation.rotate(Vec3(al.mDirection.x, al.mDirection.y, al.mDirection.z));
      l.direction = lengthSquared(d) > 0.0f ? normalize(d) : Vec3(0, -1, 0);
      l.intensity = Vec3(al.mColorDiffuse.r, al.mColorDiffuse.g, al.mColorDiffuse.b);
      if (l.kind == PunctualKind::Spot) {
        float outer = std::clamp(al.mAngleOuterCone, 1e-3f, 0.5f * kPi), inner = std::clamp(al.mAngleInnerCone, 0.0f, outer);
        l.cosOuter = std::cos(outer), l.cosInner = std::cos(inner);
      }
      try {
        scene.addPunctualLight(l, al.mName.C_Str());
      } catch (const Error& e) {
        std::fprintf(stderr, "photonvr: warning: '%s': light skipped: %s\n", path.c_str(), e.what());
      }
    }
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
    std::vector<Vec2> uvs[2];
    for (int set = 0; set < 2; ++set)
      if (mesh->HasTextureCoords(unsigned(set))) {
        uvs[set].resize(mesh->mNumVertices);
        for (unsigned v = 0; v < mesh->mNumVertices; ++v)
          uvs[set][v] = {mesh->mTextureCoords[set][v].x, mesh->mTextureCoords[set][v].y};
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
    scene.addMesh(meshName, vertices, normals, uvs, indices, material);
  }
  std::optional<FileCamera> camera = gltf ? gltfCamera(gltf->doc) : std::nullopt;
  if (camera) {  // where the import puts the file: scale, rotate, translate
    Pose& pose = camera->pose;
    const Vec3 forward = options.rotation.rotate(pose.toWorldDir({0, 0, -1}) * options.scale);
    const Vec3 up = options.rotation.rotate(pose.toWorldDir({0, 1, 0}) * options.scale);
    pose.position = options.rotation.rotate(pose.position * options.scale) + options.translation;
    pose.orientation = lookAtOrientation(pose.position, pose.position + normalize(forward), normalize(up));
  }
  return camera;
}

}  // namespace pvr
