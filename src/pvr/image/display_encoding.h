#pragma once
// A linear-RGB pixel as a display image stores it: 8-bit sRGB-encoded (the PNG's bytes, for
// *_SRGB swapchain formats that decode on read), 8-bit linear (UNORM formats), or RGBA half
// floats; and a depth as a reversed-Z value for the headset's depth layer. Written once for the
// CPU staging path and the CUDA hand-over kernel.
#include <cmath>
#include <cstdint>
#include <cstring>

#include "pvr/math/vec.h"

namespace pvr {

enum class DisplayEncoding : int {
  Rgba8Srgb = 0,   ///< bytes R, G, B, A; sRGB-encoded colour
  Bgra8Srgb = 1,   ///< bytes B, G, R, A; sRGB-encoded colour
  Rgba8Linear = 2, ///< bytes R, G, B, A; linear colour (UNORM formats)
  Bgra8Linear = 3,
  Rgba16Float = 4, ///< four IEEE half floats, linear
};

PVR_HOST_DEVICE inline int displayBytesPerPixel(DisplayEncoding e) { return e == DisplayEncoding::Rgba16Float ? 8 : 4; }

// x if finite, else 0: NaN and infinities show black, as in the PNG.
PVR_HOST_DEVICE inline float finiteOrZero(float x) { return x - x == 0.0f ? x : 0.0f; }

PVR_HOST_DEVICE inline float srgbEncode(float v) {
  v = fminf(fmaxf(finiteOrZero(v), 0.0f), 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
}

// 255 * v rounded half away from zero, as the PNG writer does.
PVR_HOST_DEVICE inline uint32_t unorm8(float v01) { return uint32_t(lroundf(255.0f * v01)); }

// IEEE 754 binary16 of a float, rounded to nearest even; infinities and NaN kept.
PVR_HOST_DEVICE inline uint16_t floatToHalf(float f) {
  uint32_t x = floatBits(f);
  uint32_t sign = (x >> 16) & 0x8000u, exponent = (x >> 23) & 0xffu, mantissa = x & 0x7fffffu;
  if (exponent == 0xffu) return uint16_t(sign | 0x7c00u | (mantissa ? 0x200u : 0u));
  int e = int(exponent) - 127 + 15;
  if (e >= 31) return uint16_t(sign | 0x7c00u);
  if (e <= 0) {  // subnormal half or zero
    if (e < -10) return uint16_t(sign);
    mantissa |= 0x800000u;
    uint32_t shift = uint32_t(14 - e);
    uint32_t half = mantissa >> shift, rest = mantissa & ((1u << shift) - 1u), midpoint = 1u << (shift - 1u);
    if (rest > midpoint || (rest == midpoint && (half & 1u))) ++half;
    return uint16_t(sign | half);
  }
  uint32_t half = (uint32_t(e) << 10) | (mantissa >> 13), rest = mantissa & 0x1fffu;
  if (rest > 0x1000u || (rest == 0x1000u && (half & 1u))) ++half;  // may carry into the exponent: still right
  return uint16_t(sign | half);
}

// Writes one pixel at `out` (displayBytesPerPixel bytes), colour scaled by `exposure`, alpha 1.
PVR_HOST_DEVICE inline void encodeDisplayPixel(Vec3 linear, float exposure, DisplayEncoding e, unsigned char* out) {
  float c[3] = {finiteOrZero(linear.x * exposure), finiteOrZero(linear.y * exposure), finiteOrZero(linear.z * exposure)};
  if (e == DisplayEncoding::Rgba16Float) {
    uint16_t h[4];
    for (int i = 0; i < 3; ++i) h[i] = floatToHalf(fmaxf(c[i], 0.0f));
    h[3] = 0x3c00u;  // 1.0
    memcpy(out, h, 8);
    return;
  }
  const bool srgb = e == DisplayEncoding::Rgba8Srgb || e == DisplayEncoding::Bgra8Srgb;
  const bool bgr = e == DisplayEncoding::Bgra8Srgb || e == DisplayEncoding::Bgra8Linear;
  uint32_t byte[3];
  for (int i = 0; i < 3; ++i) {
    float v = fminf(fmaxf(c[i], 0.0f), 1.0f);
    byte[i] = unorm8(srgb ? srgbEncode(v) : v);
  }
  out[0] = (unsigned char)byte[bgr ? 2 : 0];
  out[1] = (unsigned char)byte[1];
  out[2] = (unsigned char)byte[bgr ? 0 : 2];
  out[3] = 255;
}

// Depth for a reversed-Z depth image with the far plane at infinity: nearZ / z, so 1 at nearZ,
// 0 at infinity (and where nothing was hit); OpenXR's depth layer then has nearZ = +inf,
// farZ = nearZ (the runtime's names for the distances of depth 0 and 1).
PVR_HOST_DEVICE inline float reversedDepth(float inverseDepth, float nearZ) {
  float d = inverseDepth * nearZ;
  return fminf(fmaxf(finiteOrZero(d), 0.0f), 1.0f);
}

}  // namespace pvr
