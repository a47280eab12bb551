#pragma once
// Textures for materials, written once for host and device: RGBA8 texels (colour sRGB-encoded,
// alpha linear) with a full mip chain in one array, glTF's wrap modes and KHR_texture_transform,
// bilinear filtering within a level and linear blending between levels, the level chosen by a
// ray cone's footprint (Akenine-Moller et al. 2019, "Texture Level of Detail Strategies for
// Real-Time Ray Tracing").
#include <cstdint>

#include "pvr/math/vec.h"

namespace pvr {

enum class WrapMode : uint32_t { Repeat = 0, ClampToEdge = 1, MirroredRepeat = 2 };

constexpr int kMaxTextureLevels = 16;  // 32768 x 32768 at most

// A texture as the algorithm code reads it.
struct TextureView {
  const uint32_t* texels = nullptr;  ///< all levels, level 0 first; byte 0 = R ... byte 3 = A
  uint32_t levelOffset[kMaxTextureLevels] = {};
  int width = 0, height = 0, levels = 0;  ///< level 0's size
  WrapMode wrapS = WrapMode::Repeat, wrapT = WrapMode::Repeat;
  bool srgb = true;  ///< RGB is sRGB-encoded (colour textures); false: linear (data textures)
};

struct Rgba {
  Vec3 rgb{1, 1, 1};
  float a = 1.0f;
};

// A material's use of a texture: which one, which UV set, and KHR_texture_transform.
struct TextureRef {
  int32_t texture = -1;  ///< -1: none
  uint32_t texCoord = 0;  ///< UV set 0 or 1
  Vec2 offset{0, 0}, scale{1, 1};
  float rotation = 0.0f;  ///< radians, counter-clockwise in UV space (glTF's convention)
  PVR_HOST_DEVICE bool present() const { return texture >= 0; }
  // glTF's transform: translation * rotation * scale applied to (u, v).
  PVR_HOST_DEVICE Vec2 transform(Vec2 uv) const {
    float c = cosf(rotation), s = sinf(rotation);
    Vec2 scaled{uv.x * scale.x, uv.y * scale.y};
    return {c * scaled.x + s * scaled.y + offset.x, -s * scaled.x + c * scaled.y + offset.y};
  }
};

#define PVR_SRGB_TO_LINEAR_VALUES \
    0x0.0p+0f, 0x1.3e45680000000p-12f, 0x1.3e45680000000p-11f, 0x1.dd681c0000000p-11f, 0x1.3e45680000000p-10f, 0x1.8dd6c20000000p-10f, \
    0x1.dd681c0000000p-10f, 0x1.167cba0000000p-9f, 0x1.3e45680000000p-9f, 0x1.660e140000000p-9f, 0x1.8dd6c20000000p-9f, 0x1.b6a31c0000000p-9f, \
    0x1.e1e31e0000000p-9f, 0x1.07c38c0000000p-8f, 0x1.1fcc2c0000000p-8f, 0x1.390ffa0000000p-8f, 0x1.53936c0000000p-8f, 0x1.6f5ade0000000p-8f, \
    0x1.8c6a940000000p-8f, 0x1.aac6c00000000p-8f, 0x1.ca73820000000p-8f, 0x1.eb74e20000000p-8f, 0x1.06e76c0000000p-7f, 0x1.18c2a60000000p-7f, \
    0x1.2b4e0a0000000p-7f, 0x1.3e8b7c0000000p-7f, 0x1.527cd60000000p-7f, 0x1.6723ee0000000p-7f, 0x1.7c82920000000p-7f, 0x1.929a880000000p-7f, \
    0x1.a96d920000000p-7f, 0x1.c0fd680000000p-7f, 0x1.d94bbe0000000p-7f, 0x1.f25a440000000p-7f, 0x1.0615520000000p-6f, 0x1.135f3e0000000p-6f, \
    0x1.210bb80000000p-6f, 0x1.2f1b8c0000000p-6f, 0x1.3d8f840000000p-6f, 0x1.4c68660000000p-6f, 0x1.5ba6fa0000000p-6f, 0x1.6b4c040000000p-6f, \
    0x1.7b58420000000p-6f, 0x1.8bcc740000000p-6f, 0x1.9ca9580000000p-6f, 0x1.adefaa0000000p-6f, 0x1.bfa0200000000p-6f, 0x1.d1bb740000000p-6f, \
    0x1.e4425a0000000p-6f, 0x1.f735860000000p-6f, 0x1.054ad40000000p-5f, 0x1.0f31ba0000000p-5f, 0x1.194fcc0000000p-5f, 0x1.23a55e0000000p-5f, \
    0x1.2e32c80000000p-5f, 0x1.38f8600000000p-5f, 0x1.43f6780000000p-5f, 0x1.4f2d640000000p-5f, 0x1.5a9d760000000p-5f, 0x1.6647020000000p-5f, \
    0x1.722a560000000p-5f, 0x1.7e47c80000000p-5f, 0x1.8a9fa40000000p-5f, 0x1.97323a0000000p-5f, 0x1.a3ffd80000000p-5f, 0x1.b108d00000000p-5f, \
    0x1.be4d6c0000000p-5f, 0x1.cbcdfa0000000p-5f, 0x1.d98ac60000000p-5f, 0x1.e7841c0000000p-5f, 0x1.f5ba480000000p-5f, 0x1.0216ca0000000p-4f, \
    0x1.096f260000000p-4f, 0x1.10e65c0000000p-4f, 0x1.187c900000000p-4f, 0x1.2031e80000000p-4f, 0x1.2806880000000p-4f, 0x1.2ffa920000000p-4f, \
    0x1.380e2a0000000p-4f, 0x1.4041740000000p-4f, 0x1.4894940000000p-4f, 0x1.5107ac0000000p-4f, 0x1.599ade0000000p-4f, 0x1.624e4e0000000p-4f, \
    0x1.6b221e0000000p-4f, 0x1.7416700000000p-4f, 0x1.7d2b660000000p-4f, 0x1.8661200000000p-4f, 0x1.8fb7c00000000p-4f, 0x1.992f680000000p-4f, \
    0x1.a2c83a0000000p-4f, 0x1.ac82560000000p-4f, 0x1.b65ddc0000000p-4f, 0x1.c05aec0000000p-4f, 0x1.ca79a80000000p-4f, 0x1.d4ba300000000p-4f, \
    0x1.df1ca20000000p-4f, 0x1.e9a1200000000p-4f, 0x1.f447ca0000000p-4f, 0x1.ff10bc0000000p-4f, 0x1.04fe0c0000000p-3f, 0x1.0a84fe0000000p-3f, \
    0x1.101d440000000p-3f, 0x1.15c6ee0000000p-3f, 0x1.1b82080000000p-3f, 0x1.214ea60000000p-3f, 0x1.272cd40000000p-3f, 0x1.2d1ca20000000p-3f, \
    0x1.331e1e0000000p-3f, 0x1.3931580000000p-3f, 0x1.3f56600000000p-3f, 0x1.458d420000000p-3f, 0x1.4bd60e0000000p-3f, 0x1.5230d40000000p-3f, \
    0x1.589da00000000p-3f, 0x1.5f1c840000000p-3f, 0x1.65ad8a0000000p-3f, 0x1.6c50c40000000p-3f, 0x1.73063e0000000p-3f, 0x1.79ce060000000p-3f, \
    0x1.80a82e0000000p-3f, 0x1.8794c00000000p-3f, 0x1.8e93cc0000000p-3f, 0x1.95a55e0000000p-3f, 0x1.9cc9860000000p-3f, 0x1.a400520000000p-3f, \
    0x1.ab49ce0000000p-3f, 0x1.b2a60a0000000p-3f, 0x1.ba15120000000p-3f, 0x1.c196f40000000p-3f, 0x1.c92bbe0000000p-3f, 0x1.d0d37c0000000p-3f, \
    0x1.d88e3e0000000p-3f, 0x1.e05c0e0000000p-3f, 0x1.e83cfc0000000p-3f, 0x1.f031160000000p-3f, 0x1.f838660000000p-3f, 0x1.00297e0000000p-2f, \
    0x1.0440720000000p-2f, 0x1.0861160000000p-2f, 0x1.0c8b700000000p-2f, 0x1.10bf860000000p-2f, 0x1.14fd600000000p-2f, 0x1.1945020000000p-2f, \
    0x1.1d96760000000p-2f, 0x1.21f1be0000000p-2f, 0x1.2656e40000000p-2f, 0x1.2ac5ec0000000p-2f, 0x1.2f3ede0000000p-2f, 0x1.33c1c00000000p-2f, \
    0x1.384e980000000p-2f, 0x1.3ce56c0000000p-2f, 0x1.4186420000000p-2f, 0x1.4631200000000p-2f, 0x1.4ae60e0000000p-2f, 0x1.4fa5100000000p-2f, \
    0x1.546e2c0000000p-2f, 0x1.59416c0000000p-2f, 0x1.5e1ed00000000p-2f, 0x1.6306640000000p-2f, 0x1.67f82a0000000p-2f, 0x1.6cf4280000000p-2f, \
    0x1.71fa680000000p-2f, 0x1.770aec0000000p-2f, 0x1.7c25bc0000000p-2f, 0x1.814adc0000000p-2f, 0x1.867a540000000p-2f, 0x1.8bb4280000000p-2f, \
    0x1.90f8600000000p-2f, 0x1.9647000000000p-2f, 0x1.9ba0100000000p-2f, 0x1.a103940000000p-2f, 0x1.a671920000000p-2f, 0x1.abea100000000p-2f, \
    0x1.b16d140000000p-2f, 0x1.b6faa40000000p-2f, 0x1.bc92c60000000p-2f, 0x1.c2357e0000000p-2f, 0x1.c7e2d20000000p-2f, 0x1.cd9aca0000000p-2f, \
    0x1.d35d6a0000000p-2f, 0x1.d92ab60000000p-2f, 0x1.df02b80000000p-2f, 0x1.e4e5700000000p-2f, 0x1.ead2e80000000p-2f, 0x1.f0cb260000000p-2f, \
    0x1.f6ce2c0000000p-2f, 0x1.fcdc000000000p-2f, 0x1.017a560000000p-1f, 0x1.048c180000000p-1f, 0x1.07a34a0000000p-1f, 0x1.0abfee0000000p-1f, \
    0x1.0de2080000000p-1f, 0x1.11099a0000000p-1f, 0x1.1436a80000000p-1f, 0x1.1769320000000p-1f, 0x1.1aa13e0000000p-1f, 0x1.1ddeca0000000p-1f, \
    0x1.2121de0000000p-1f, 0x1.246a7a0000000p-1f, 0x1.27b8a00000000p-1f, 0x1.2b0c540000000p-1f, 0x1.2e65980000000p-1f, 0x1.31c46e0000000p-1f, \
    0x1.3528dc0000000p-1f, 0x1.3892e00000000p-1f, 0x1.3c02800000000p-1f, 0x1.3f77bc0000000p-1f, 0x1.42f29a0000000p-1f, 0x1.4673180000000p-1f, \
    0x1.49f93e0000000p-1f, 0x1.4d850a0000000p-1f, 0x1.5116820000000p-1f, 0x1.54ada40000000p-1f, 0x1.584a780000000p-1f, 0x1.5becfe0000000p-1f, \
    0x1.5f95380000000p-1f, 0x1.6343280000000p-1f, 0x1.66f6d40000000p-1f, 0x1.6ab03a0000000p-1f, 0x1.6e6f600000000p-1f, 0x1.7234480000000p-1f, \
    0x1.75fef40000000p-1f, 0x1.79cf640000000p-1f, 0x1.7da59e0000000p-1f, 0x1.8181a40000000p-1f, 0x1.8563780000000p-1f, 0x1.894b1c0000000p-1f, \
    0x1.8d38920000000p-1f, 0x1.912bde0000000p-1f, 0x1.9525000000000p-1f, 0x1.9923fe0000000p-1f, 0x1.9d28d80000000p-1f, 0x1.a133920000000p-1f, \
    0x1.a5442c0000000p-1f, 0x1.a95aac0000000p-1f, 0x1.ad77100000000p-1f, 0x1.b1995e0000000p-1f, 0x1.b5c1980000000p-1f, 0x1.b9efbe0000000p-1f, \
    0x1.be23d40000000p-1f, 0x1.c25dde0000000p-1f, 0x1.c69ddc0000000p-1f, 0x1.cae3d20000000p-1f, 0x1.cf2fc00000000p-1f, 0x1.d381aa0000000p-1f, \
    0x1.d7d9940000000p-1f, 0x1.dc377e0000000p-1f, 0x1.e09b6a0000000p-1f, 0x1.e5055c0000000p-1f, 0x1.e975560000000p-1f, 0x1.edeb5c0000000p-1f, \
    0x1.f2676c0000000p-1f, 0x1.f6e98c0000000p-1f, 0x1.fb71bc0000000p-1f, 0x1p+0f,

inline constexpr float kSrgbToLinearHost[256] = {PVR_SRGB_TO_LINEAR_VALUES};
#ifdef __CUDACC__
static __device__ __constant__ float kSrgbToLinearDevice[256] = {PVR_SRGB_TO_LINEAR_VALUES};
#endif

// The linear value of an 8-bit sRGB code (the same table on host and device).
PVR_HOST_DEVICE inline float srgb8ToLinear(uint32_t code) {
#ifdef __CUDA_ARCH__
  return kSrgbToLinearDevice[code & 255u];
#else
  return kSrgbToLinearHost[code & 255u];
#endif
}

// A texel coordinate under a wrap mode, for a level `size` texels wide.
PVR_HOST_DEVICE inline int wrapTexel(int i, int size, WrapMode mode) {
  if (mode == WrapMode::ClampToEdge) return i < 0 ? 0 : (i >= size ? size - 1 : i);
  if (mode == WrapMode::MirroredRepeat) {
    int period = 2 * size;
    int m = i % period;
    if (m < 0) m += period;
    return m < size ? m : period - 1 - m;
  }
  int m = i % size;
  return m < 0 ? m + size : m;
}

PVR_HOST_DEVICE inline Rgba decodeTexel(uint32_t t, bool srgb) {
  Rgba c;
  uint32_t r = t & 255u, g = (t >> 8) & 255u, b = (t >> 16) & 255u;
  c.rgb = srgb ? Vec3(srgb8ToLinear(r), srgb8ToLinear(g), srgb8ToLinear(b))
               : Vec3(float(r) * (1.0f / 255.0f), float(g) * (1.0f / 255.0f), float(b) * (1.0f / 255.0f));
  c.a = float(t >> 24) * (1.0f / 255.0f);
  return c;
}

PVR_HOST_DEVICE inline int levelSize(int size0, int level) {
  int s = size0 >> level;
  return s > 0 ? s : 1;
}

// One texel of a level, wrapped.
PVR_HOST_DEVICE inline Rgba fetchTexel(const TextureView& t, int level, int x, int y) {
  int w = levelSize(t.width, level), h = levelSize(t.height, level);
  x = wrapTexel(x, w, t.wrapS);
  y = wrapTexel(y, h, t.wrapT);
  return decodeTexel(t.texels[t.levelOffset[level] + uint32_t(y) * uint32_t(w) + uint32_t(x)], t.srgb);
}

// Bilinear within a level; (u, v) in texture space (0..1 spans the texture once, v down the rows).
PVR_HOST_DEVICE inline Rgba sampleLevel(const TextureView& t, int level, Vec2 uv) {
  int w = levelSize(t.width, level), h = levelSize(t.height, level);
  float x = uv.x * float(w) - 0.5f, y = uv.y * float(h) - 0.5f;
  float fx = floorf(x), fy = floorf(y);
  int x0 = int(fx), y0 = int(fy);
  float ax = x - fx, ay = y - fy;
  Rgba c00 = fetchTexel(t, level, x0, y0), c10 = fetchTexel(t, level, x0 + 1, y0);
  Rgba c01 = fetchTexel(t, level, x0, y0 + 1), c11 = fetchTexel(t, level, x0 + 1, y0 + 1);
  Rgba out;
  out.rgb = (c00.rgb * (1 - ax) + c10.rgb * ax) * (1 - ay) + (c01.rgb * (1 - ax) + c11.rgb * ax) * ay;
  out.a = (c00.a * (1 - ax) + c10.a * ax) * (1 - ay) + (c01.a * (1 - ax) + c11.a * ax) * ay;
  return out;
}

// Trilinear: level `lod` (clamped to the chain), blending the two nearest levels.
PVR_HOST_DEVICE inline Rgba sampleTexture(const TextureView& t, Vec2 uv, float lod) {
  float maxLevel = float(t.levels - 1);
  lod = lod == lod ? fminf(fmaxf(lod, 0.0f), maxLevel) : 0.0f;
  int l0 = int(floorf(lod));
  float f = lod - float(l0);
  Rgba a = sampleLevel(t, l0, uv);
  if (f == 0.0f || l0 + 1 >= t.levels) return a;
  Rgba b = sampleLevel(t, l0 + 1, uv);
  return {a.rgb * (1 - f) + b.rgb * f, a.a * (1 - f) + b.a * f};
}

// The ray cone's level of detail at a hit: lambda = 0.5 log2(texel area / world area of the
// triangle) + log2(cone width / |cos|), with the texel area over the texture's level-0 size.
PVR_HOST_DEVICE inline float rayConeLod(float uvArea, int width, int height, float worldArea, float coneWidth, float cosTheta) {
  if (!(coneWidth > 0.0f) || !(worldArea > 0.0f) || !(uvArea > 0.0f)) return 0.0f;
  float texelArea = uvArea * float(width) * float(height);
  return 0.5f * log2f(texelArea / worldArea) + log2f(coneWidth / fmaxf(fabsf(cosTheta), 1e-4f));
}

}  // namespace pvr
