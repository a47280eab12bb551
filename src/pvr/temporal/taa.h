#pragma once
// Temporal anti-aliasing (TAA) of one eye's image, host+device: each pixel's displayed colour
// blends the current frame with the previous displayed frame, reprojected through the current
// frame's depth and both frames' cameras (head motion). The reprojected history is
//  - rejected where the previous frame saw another surface there (disocclusion: its depth does
//    not match) or did not see the point at all (off its image): the pixel restarts from the
//    current frame;
//  - clamped to the colour range of the pixel's current neighbourhood, so that what changed
//    (moving light, a mirror's reflection) does not leave a ghost.
// What was emitted along a pixel's path (a light or the sky seen, directly or in a mirror) has no
// noise and is rendered at the pixel centre as the reference is, so where the eye pass reports it
// it is shown as rendered and kept out of the history: resampling a moving head's history mixes
// neighbours, and beside a light (tens of times its neighbours' radiance, inside their clamp range)
// that mix compounds frame after frame into a bright rim.
// Foveated frames are reconstructed from samples several pixels apart in the periphery; the
// neighbourhood there is scaled to the local sample spacing, so it spans neighbouring samples as
// a 3x3 neighbourhood does at full resolution.
#include "pvr/camera/stereo_rig.h"
#include "pvr/stereo/stereo_reuse.h"

namespace pvr {

struct TaaParams {
  float blend = 0.1f;            ///< weight of the current frame (1: no history); in (0, 1]
  float depthTolerance = 0.02f;  ///< relative depth difference beyond which history is another surface
  bool clampToNeighbourhood = true;
};

// The temporal stage's options: each eye's displayed image blends in the previous one,
// reprojected by depth and the head's motion.
struct TemporalOptions {
  bool enabled = false;
  TaaParams taa;
};

// The current frame's emitted part per pixel (null: not known; all of the image is resolved).
// Under stereo reuse a reused pixel's is the left eye's at the pixel it reused.
struct TaaEmitted {
  const Vec3* emitted = nullptr;
  const uint32_t* reusedFrom = nullptr;
  const Vec3* sourceEmitted = nullptr;
};

// One eye's frame and its history, as device or host pointers.
struct TaaView {
  EyeCamera camera, previousCamera;
  const Vec3* current = nullptr;
  const float* inverseDepth = nullptr;   ///< current frame, per pixel (0: nothing hit)
  const float* sampleSpacing = nullptr;  ///< current frame, pixels between samples; null: 1
  const Vec3* history = nullptr;         ///< previous resolved frame (previousCamera's size); null: none
  const float* historyInverseDepth = nullptr;
  TaaEmitted emission;
  TaaParams params;
};

// The emitted part of the current frame's pixel (zero where it is not known).
PVR_HOST_DEVICE inline Vec3 emittedAt(const TaaView& v, size_t pixel) {
  const TaaEmitted& e = v.emission;
  if (!e.emitted) return Vec3(0.0f);
  const uint32_t source = e.reusedFrom ? e.reusedFrom[pixel] : kNotReused;
  return source != kNotReused ? e.sourceEmitted[source] : e.emitted[pixel];
}

// What the history accumulates of the current frame's pixel: all of it but the emitted part.
PVR_HOST_DEVICE inline Vec3 resolvedPart(const TaaView& v, size_t pixel) {
  return v.emission.emitted ? max(v.current[pixel] - emittedAt(v, pixel), Vec3(0.0f)) : v.current[pixel];
}

// Pixel (x, y) of a colour or depth image, the nearest edge pixel outside it.
template <class T>
PVR_HOST_DEVICE inline T clampedPixel(const T* image, int width, int height, int x, int y) {
  x = x < 0 ? 0 : (x >= width ? width - 1 : x);
  y = y < 0 ? 0 : (y >= height ? height - 1 : y);
  return image[size_t(y) * width + x];
}

// Catmull-Rom weights of the four samples around a point at fraction t past the second one.
PVR_HOST_DEVICE inline void catmullRomWeights(float t, float w[4]) {
  w[0] = t * (-0.5f + t * (1.0f - 0.5f * t));
  w[1] = 1.0f + t * t * (-2.5f + 1.5f * t);
  w[2] = t * (0.5f + t * (2.0f - 1.5f * t));
  w[3] = t * t * (-0.5f + 0.5f * t);
}

// The image at continuous pixel position (px, py) by Catmull-Rom (bicubic) interpolation: unlike
// bilinear it does not blur the history a little more every frame the head moves. At a pixel
// centre it returns that pixel.
PVR_HOST_DEVICE inline Vec3 sampleCatmullRom(const Vec3* image, int width, int height, float px, float py) {
  float fx = px - 0.5f, fy = py - 0.5f;
  float bx = floorf(fx), by = floorf(fy);
  float wx[4], wy[4];
  catmullRomWeights(fx - bx, wx);
  catmullRomWeights(fy - by, wy);
  Vec3 sum{0, 0, 0};
  for (int j = 0; j < 4; ++j) {
    Vec3 row{0, 0, 0};
    for (int i = 0; i < 4; ++i) row += clampedPixel(image, width, height, int(bx) - 1 + i, int(by) - 1 + j) * wx[i];
    sum += row * wy[j];
  }
  return sum;
}

// Where pixel (x, y)'s centre was in the previous frame, and the inverse depth it had there. Points
// at infinity (nothing hit) move with the head's rotation only. False if the previous eye did not
// see it (behind it, or outside its image).
PVR_HOST_DEVICE inline bool reprojectToPrevious(const TaaView& v, int x, int y, float& px, float& py,
                                                float& previousInverseDepth) {
  float cx = float(x) + 0.5f, cy = float(y) + 0.5f;
  float w = v.inverseDepth[size_t(y) * v.camera.width + x];
  bool inFront;
  if (w > 0.0f) {
    Vec3 world = v.camera.pointAt(cx, cy, w);
    previousInverseDepth = v.previousCamera.inverseDepthOf(world);
    inFront = v.previousCamera.project(world, px, py);
  } else {
    previousInverseDepth = 0.0f;
    inFront = v.previousCamera.projectDirection(v.camera.pose.toWorldDir(v.camera.localDirection(cx, cy)), px, py);
  }
  return inFront && v.previousCamera.containsPixel(px, py);
}

// Pixels between a frame's samples at pixel (x, y): 1 at full resolution, the mask's local spacing
// when foveated.
PVR_HOST_DEVICE inline int sampleStep(const TaaView& v, int x, int y) {
  if (!v.sampleSpacing) return 1;
  float s = v.sampleSpacing[size_t(y) * v.camera.width + x];
  return s > 1.5f ? int(s + 0.5f) : 1;
}

// Whether the previous frame saw a surface at the expected depth around (px, py). At full
// resolution: one of the four pixels around it, or their bilinear blend, within the tolerance
// (inverse depths compared relatively compare depths relatively; background, 0, matches
// background). Where the current
// frame was rebuilt from samples `step` pixels apart its depth is a blend across that distance
// (silhouettes included), so the depth is accepted anywhere within the range the previous frame
// had within one step: a moving gaze alone does not throw history away.
PVR_HOST_DEVICE inline bool previousSawSameSurface(const TaaView& v, float px, float py, float expected, int step) {
  const int w = v.previousCamera.width, h = v.previousCamera.height;
  const float tolerance = v.params.depthTolerance;
  if (step == 1) {
    const float fx = px - 0.5f, fy = py - 0.5f;
    const int x0 = int(floorf(fx)), y0 = int(floorf(fy));
    const float tx = fx - floorf(fx), ty = fy - floorf(fy);
    float bilinear = 0.0f;
    bool near = false;
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        float d = clampedPixel(v.historyInverseDepth, w, h, x0 + i, y0 + j);
        near = near || fabsf(d - expected) <= tolerance * fmaxf(d, expected);
        bilinear += d * (i ? tx : 1.0f - tx) * (j ? ty : 1.0f - ty);
      }
    // Inverse depth is affine across a plane, so its bilinear blend is exact there even where
    // the plane is seen at a grazing angle; a single close pixel keeps silhouettes.
    return near || fabsf(bilinear - expected) <= tolerance * fmaxf(bilinear, expected);
  }
  int cx = int(px), cy = int(py);
  float lo = INFINITY, hi = 0.0f;
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i) {
      float d = clampedPixel(v.historyInverseDepth, w, h, cx + i * step, cy + j * step);
      lo = fminf(lo, d);
      hi = fmaxf(hi, d);
    }
  return expected >= lo * (1.0f - tolerance) && expected <= hi * (1.0f + tolerance);
}

// The current frame's colour range around pixel (x, y): a 3x3 neighbourhood whose step is the
// local sample spacing (one pixel at full resolution).
PVR_HOST_DEVICE inline void neighbourhoodRange(const TaaView& v, int x, int y, Vec3& lo, Vec3& hi) {
  const int w = v.camera.width, h = v.camera.height;
  const int step = sampleStep(v, x, y);
  lo = hi = resolvedPart(v, size_t(y) * w + x);
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i) {
      const int qx = x + i * step, qy = y + j * step;
      const Vec3 c = resolvedPart(v, size_t(qy < 0 ? 0 : qy >= h ? h - 1 : qy) * w + (qx < 0 ? 0 : qx >= w ? w - 1 : qx));
      lo = min(lo, c);
      hi = max(hi, c);
    }
}

// Reprojected positions this close to a pixel centre read that pixel exactly.
constexpr float kTaaSnapPixels = 2e-3f;

// One pixel's resolve: what the history keeps and what is displayed (the same but for the emitted
// part, added back), and whether the history contributed (false: first frame, disocclusion, or
// the point was off the previous image).
struct TaaPixel {
  Vec3 history{0, 0, 0};
  Vec3 displayed{0, 0, 0};
  bool usedHistory = false;
};

PVR_HOST_DEVICE inline TaaPixel resolveTemporalPixel(const TaaView& v, int x, int y) {
  const size_t pixel = size_t(y) * v.camera.width + x;
  const Vec3 current = resolvedPart(v, pixel);
  const Vec3 emitted = emittedAt(v, pixel);
  TaaPixel out;
  out.history = current;
  out.displayed = v.current[pixel];
  if (!v.history) return out;
  float px, py, expected;
  if (!reprojectToPrevious(v, x, y, px, py, expected) ||
      !previousSawSameSurface(v, px, py, expected, sampleStep(v, x, y)))
    return out;
  // A still head reprojects onto the pixel centres up to float rounding (about 1e-4 pixel); read
  // those pixels as they are, or Catmull-Rom mixes a rounding's worth of the neighbours in every
  // frame and the history settles off the image by that much times 1 / blend (at a light's edge).
  const float snappedX = floorf(px) + 0.5f, snappedY = floorf(py) + 0.5f;
  if (fabsf(px - snappedX) < kTaaSnapPixels && fabsf(py - snappedY) < kTaaSnapPixels) px = snappedX, py = snappedY;
  Vec3 history = sampleCatmullRom(v.history, v.previousCamera.width, v.previousCamera.height, px, py);
  if (v.params.clampToNeighbourhood) {
    Vec3 lo, hi;
    neighbourhoodRange(v, x, y, lo, hi);
    history = min(max(history, lo), hi);
  } else {
    history = max(history, Vec3(0.0f));  // Catmull-Rom's lobes can undershoot
  }
  out.usedHistory = true;
  out.history = history + (current - history) * v.params.blend;
  out.displayed = out.history + emitted;
  return out;
}

}  // namespace pvr
