#include "pvr/scene/texture_file.h"

#define STB_IMAGE_IMPLEMENTATION
#define STBI_FAILURE_USERMSG
#include <stb_image.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace pvr {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

// The file itself, or one in its folder whose name matches ignoring case; empty if none.
std::string findCaseInsensitive(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) return path;
  fs::path p(path);
  fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  std::string want = lower(p.filename().string());
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (lower(it->path().filename().string()) == want) return it->path().string();
  return {};
}

std::string cacheKey(const std::string& key, bool srgb, WrapMode s, WrapMode t) {
  return key + (srgb ? "|srgb|" : "|linear|") + std::to_string(int(s)) + std::to_string(int(t));
}

}  // namespace

int32_t TextureLoader::decoded(const std::string& key, unsigned char* rgba, int width, int height, bool srgb, WrapMode s,
                               WrapMode t) {
  std::vector<uint32_t> texels(size_t(width) * height);
  for (size_t i = 0; i < texels.size(); ++i)
    texels[i] = uint32_t(rgba[4 * i]) | uint32_t(rgba[4 * i + 1]) << 8 | uint32_t(rgba[4 * i + 2]) << 16 | uint32_t(rgba[4 * i + 3]) << 24;
  int32_t index = int32_t(scene_.addTexture(key, width, height, std::move(texels), srgb, s, t));
  cache_[cacheKey(key, srgb, s, t)] = index;
  return index;
}

int32_t TextureLoader::fromFile(const std::string& path, bool srgb, WrapMode s, WrapMode t) {
  auto cached = cache_.find(cacheKey(path, srgb, s, t));
  if (cached != cache_.end()) return cached->second;
  std::string found = findCaseInsensitive(path);
  int w = 0, h = 0, channels = 0;
  unsigned char* rgba = found.empty() ? nullptr : stbi_load(found.c_str(), &w, &h, &channels, 4);
  if (!rgba) {
    ++warnings_;
    std::fprintf(stderr, "photonvr: warning: texture '%s' %s; its material keeps its constant colour\n", path.c_str(),
                 found.empty() ? "not found" : ("cannot be read: " + std::string(stbi_failure_reason())).c_str());
    cache_[cacheKey(path, srgb, s, t)] = -1;
    return -1;
  }
  int32_t index = decoded(path, rgba, w, h, srgb, s, t);
  stbi_image_free(rgba);
  return index;
}

int32_t TextureLoader::fromMemory(const std::string& key, const unsigned char* bytes, size_t size, bool srgb, WrapMode s,
                                  WrapMode t) {
  auto cached = cache_.find(cacheKey(key, srgb, s, t));
  if (cached != cache_.end()) return cached->second;
  int w = 0, h = 0, channels = 0;
  unsigned char* rgba = size <= size_t(1) << 31 ? stbi_load_from_memory(bytes, int(size), &w, &h, &channels, 4) : nullptr;
  if (!rgba) {
    ++warnings_;
    std::fprintf(stderr, "photonvr: warning: embedded texture %s cannot be read (%s); its material keeps its constant colour\n",
                 key.c_str(), stbi_failure_reason());
    cache_[cacheKey(key, srgb, s, t)] = -1;
    return -1;
  }
  int32_t index = decoded(key, rgba, w, h, srgb, s, t);
  stbi_image_free(rgba);
  return index;
}

int32_t TextureLoader::normalsFromHeight(int32_t height, float strength) {
  if (height < 0) return -1;
  const std::string key = "normals of texture " + std::to_string(height) + " x" + std::to_string(strength);
  auto cached = cache_.find(key);
  if (cached != cache_.end()) return cached->second;
  const TextureView& view = scene_.textureViews()[size_t(height)];
  const std::vector<uint32_t> texels = scene_.textureTexels(uint32_t(height));
  const int w = view.width, h = view.height;
  const WrapMode s = view.wrapS, t = view.wrapT;
  auto at = [&](int x, int y) { return float(texels[size_t(wrapTexel(y, h, t)) * w + wrapTexel(x, w, s)] & 255u) / 255.0f; };
  std::vector<uint32_t> normals(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      // Central differences; the surface rises where the height grows, so the normal leans away.
      float dx = 0.5f * (at(x + 1, y) - at(x - 1, y)) * strength, dUp = 0.5f * (at(x, y - 1) - at(x, y + 1)) * strength;
      Vec3 n = normalize(Vec3(-dx, -dUp, 1.0f));
      auto code = [](float c) { return uint32_t(std::lround(255.0f * std::clamp(0.5f * c + 0.5f, 0.0f, 1.0f))); };
      normals[size_t(y) * w + x] = code(n.x) | code(n.y) << 8 | code(n.z) << 16 | 255u << 24;
    }
  int32_t index = int32_t(scene_.addTexture(key, w, h, std::move(normals), false, s, t));
  cache_[key] = index;
  return index;
}

int32_t TextureLoader::fromBgra(const std::string& key, const unsigned char* bgra, int width, int height, bool srgb, WrapMode s,
                                WrapMode t) {
  auto cached = cache_.find(cacheKey(key, srgb, s, t));
  if (cached != cache_.end()) return cached->second;
  std::vector<unsigned char> rgba(size_t(width) * height * 4);
  for (size_t i = 0; i < size_t(width) * height; ++i)
    rgba[4 * i] = bgra[4 * i + 2], rgba[4 * i + 1] = bgra[4 * i + 1], rgba[4 * i + 2] = bgra[4 * i], rgba[4 * i + 3] = bgra[4 * i + 3];
  return decoded(key, rgba.data(), width, height, srgb, s, t);
}

}  // namespace pvr
