#pragma once
// Small vector types shared by host and device code.
#include <cmath>
#include <cstdint>
#include <cstring>

#include "pvr/pvr.h"

namespace pvr {

// A float's bits and back (for order-preserving keys and atomics on floats).
PVR_HOST_DEVICE inline uint32_t floatBits(float f) {
#ifdef __CUDA_ARCH__
  return __float_as_uint(f);
#else
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  return bits;
#endif
}
PVR_HOST_DEVICE inline float floatFromBits(uint32_t bits) {
#ifdef __CUDA_ARCH__
  return __uint_as_float(bits);
#else
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
#endif
}

// A float's bits as an unsigned integer ordered as the floats are, -0 as +0 (so that ties are
// those of the CPU's <): atomicMin/atomicMax keep bounds in it, radix sorts rank floats by it.
PVR_HOST_DEVICE inline uint32_t orderedBits(float v) {
  const uint32_t b = floatBits(v == 0.0f ? 0.0f : v);
  return (b & 0x80000000u) ? ~b : (b | 0x80000000u);
}
PVR_HOST_DEVICE inline float fromOrderedBits(uint32_t o) { return floatFromBits((o & 0x80000000u) ? (o & 0x7fffffffu) : ~o); }

struct Vec2 {
  float x = 0, y = 0;
};

struct Vec3 {
  float x = 0, y = 0, z = 0;
  constexpr Vec3() = default;
  PVR_HOST_DEVICE constexpr Vec3(float a, float b, float c) : x(a), y(b), z(c) {}
  PVR_HOST_DEVICE explicit constexpr Vec3(float s) : x(s), y(s), z(s) {}
  PVR_HOST_DEVICE float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  PVR_HOST_DEVICE float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  PVR_HOST_DEVICE Vec3& operator+=(Vec3 b) { x += b.x; y += b.y; z += b.z; return *this; }
  PVR_HOST_DEVICE Vec3& operator-=(Vec3 b) { x -= b.x; y -= b.y; z -= b.z; return *this; }
  PVR_HOST_DEVICE Vec3& operator*=(Vec3 b) { x *= b.x; y *= b.y; z *= b.z; return *this; }
  PVR_HOST_DEVICE Vec3& operator*=(float s) { x *= s; y *= s; z *= s; return *this; }
  PVR_HOST_DEVICE Vec3& operator/=(float s) { return *this *= 1.0f / s; }
};

PVR_HOST_DEVICE inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
PVR_HOST_DEVICE inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
PVR_HOST_DEVICE inline Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
PVR_HOST_DEVICE inline Vec3 operator*(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
PVR_HOST_DEVICE inline Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
PVR_HOST_DEVICE inline Vec3 operator*(float s, Vec3 a) { return a * s; }
PVR_HOST_DEVICE inline Vec3 operator/(Vec3 a, float s) { return a * (1.0f / s); }
PVR_HOST_DEVICE inline bool operator==(Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

PVR_HOST_DEVICE inline float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
PVR_HOST_DEVICE inline Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
PVR_HOST_DEVICE inline float lengthSquared(Vec3 a) { return dot(a, a); }
PVR_HOST_DEVICE inline float length(Vec3 a) { return std::sqrt(dot(a, a)); }
PVR_HOST_DEVICE inline Vec3 normalize(Vec3 a) { return a / length(a); }
PVR_HOST_DEVICE inline Vec3 min(Vec3 a, Vec3 b) {
  return {fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z)};
}
PVR_HOST_DEVICE inline Vec3 max(Vec3 a, Vec3 b) {
  return {fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z)};
}
PVR_HOST_DEVICE inline Vec3 abs(Vec3 a) { return {fabsf(a.x), fabsf(a.y), fabsf(a.z)}; }
PVR_HOST_DEVICE inline float maxComponent(Vec3 a) { return fmaxf(a.x, fmaxf(a.y, a.z)); }
PVR_HOST_DEVICE inline float luminance(Vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
PVR_HOST_DEVICE inline bool isFinite(Vec3 a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}
PVR_HOST_DEVICE inline bool isBlack(Vec3 a) { return a.x == 0 && a.y == 0 && a.z == 0; }

static_assert(sizeof(Vec3) == 12, "Vec3 must be three packed floats (Embree and GPU buffers)");

// Reflects d (pointing towards the surface) about the normal n.
PVR_HOST_DEVICE inline Vec3 reflect(Vec3 d, Vec3 n) { return d - n * (2.0f * dot(d, n)); }

// Axis-aligned box.
struct Bounds3 {
  Vec3 lower{INFINITY, INFINITY, INFINITY};
  Vec3 upper{-INFINITY, -INFINITY, -INFINITY};
  PVR_HOST_DEVICE void extend(Vec3 p) { lower = min(lower, p); upper = max(upper, p); }
  PVR_HOST_DEVICE bool empty() const { return lower.x > upper.x; }
  PVR_HOST_DEVICE Vec3 extent() const { return upper - lower; }
  PVR_HOST_DEVICE int longestAxis() const {
    Vec3 e = extent();
    return (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
  }
};

// Orthonormal basis around a unit normal (Duff et al. 2017, branchless).
struct Frame {
  Vec3 s, t, n;
  PVR_HOST_DEVICE static Frame fromNormal(Vec3 n) {
    float sign = copysignf(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float b = n.x * n.y * a;
    Frame f;
    f.s = {1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x};
    f.t = {b, sign + n.y * n.y * a, -n.y};
    f.n = n;
    return f;
  }
  PVR_HOST_DEVICE Vec3 toWorld(Vec3 v) const { return s * v.x + t * v.y + n * v.z; }
  PVR_HOST_DEVICE Vec3 toLocal(Vec3 v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
};

// Unit quaternion (x, y, z, w) for rigid rotations, as OpenXR's XrQuaternionf.
struct Quat {
  float x = 0, y = 0, z = 0, w = 1;
  PVR_HOST_DEVICE static Quat fromAxisAngle(Vec3 axis, float radians) {
    Vec3 a = normalize(axis) * sinf(0.5f * radians);
    return {a.x, a.y, a.z, cosf(0.5f * radians)};
  }
  PVR_HOST_DEVICE Vec3 rotate(Vec3 v) const {
    Vec3 q{x, y, z};
    Vec3 t = cross(q, v) * 2.0f;
    return v + t * w + cross(q, t);
  }
  PVR_HOST_DEVICE Quat conjugate() const { return {-x, -y, -z, w}; }
};

PVR_HOST_DEVICE inline Quat operator*(Quat a, Quat b) {
  return {a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y, a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
          a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w, a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z};
}

}  // namespace pvr
