#pragma once
// Texture images for materials, decoded with stb_image (PNG, JPEG, TGA, BMP, ...) from files or
// from a scene file's embedded bytes, and added to a Scene once per image.
#include <map>
#include <string>

#include "pvr/scene/scene.h"

namespace pvr {

class TextureLoader {
 public:
  explicit TextureLoader(Scene& scene) : scene_(scene) {}
  // The scene's texture for an image file (found case-insensitively in its folder, as the
  // 8.3 names of .3ds files need), or -1 with a warning on stderr when it cannot be read: a
  // missing texture leaves the constant colour, it does not stop the render.
  int32_t fromFile(const std::string& path, bool srgb, WrapMode s, WrapMode t);
  // The same for encoded image bytes (a .glb's embedded PNG/JPEG); `key` names it for the cache.
  int32_t fromMemory(const std::string& key, const unsigned char* bytes, size_t size, bool srgb, WrapMode s, WrapMode t);
  // Uncompressed texels (assimp's embedded aiTexel: B, G, R, A bytes per texel).
  int32_t fromBgra(const std::string& key, const unsigned char* bgra, int width, int height, bool srgb, WrapMode s, WrapMode t);
  // A tangent-space normal map made from a height (bump) map: the slopes of its first channel,
  // `strength` height units per texel at full range. -1 if `height` is -1.
  int32_t normalsFromHeight(int32_t height, float strength);
  size_t warnings() const { return warnings_; }

 private:
  int32_t decoded(const std::string& key, unsigned char* rgba, int width, int height, bool srgb, WrapMode s, WrapMode t);
  Scene& scene_;
  std::map<std::string, int32_t> cache_;
  size_t warnings_ = 0;
};

}  // namespace pvr
