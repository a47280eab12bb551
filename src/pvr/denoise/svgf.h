#pragma once
// Spatio-temporal variance-guided filtering of one eye's image (SVGF: Schied et al., HPG 2017),
// host+device, shared by the CPU and CUDA backends. Per frame:
//
//   1. demodulate: the eye pass's direct part (shadow rays) and its photon-map part (image -
//      direct) are each divided by the gather surface's albedo, so the filter sees irradiance-like
//      signals and texture detail survives; what was emitted along the path (a light or the sky
//      seen) has no noise and is left out, to be added back as it was;
//   2. accumulate: each signal, and its luminance's first two moments, blend with the history
//      reprojected through the frame's depth and both cameras (a still or turning head), the
//      history's 2x2 taps kept only where they saw the same surface (depth and normal);
//   3. variance: from the moments, or from a 7x7 neighbourhood where the history is short;
//   4. filter: a few a-trous wavelet passes (3x3 taps, weights 1/4 1/2 1/4, at steps 1, 2, 4, ...) with
//      edge-stopping weights on depth (a plane through the pixel, so slanted floors filter),
//      normals and luminance (scaled by the local standard deviation); the first pass's output
//      becomes the history;
//   5. remodulate by the same albedo and add the emitted part: a noise-free signal comes back as
//      it went in.
//
// Foveated frames are rebuilt from samples several pixels apart: every step is scaled by the
// local sample spacing, so the taps land on neighbouring samples as they do on pixels at full
// resolution. Where no guides exist (foveated eyes give only depth) the signal is the whole image.
//
// Steps 3-5 run only over the pixels an eye filters (`filtersPixel`): background has nothing to
// filter, and under stereo reuse a right pixel that took the left eye's shading shares the left
// eye's history and filter levels instead of being denoised a second time.
#include "pvr/camera/stereo_rig.h"
#include "pvr/denoise/denoise_options.h"
#include "pvr/stereo/stereo_reuse.h"
#include "pvr/temporal/taa.h"

namespace pvr {

// Normals closer than this (cosine, 26 degrees) may belong to one surface; farther, never blend.
constexpr float kDenoiseMinNormalCosine = 0.9f;
// History is short (the variance comes from the neighbourhood) below 4 frames. The bound sits a
// hair under 4: a history read through bilinear taps of 3-frame pixels comes to 3.9999..., which
// would send a whole moving eye down the neighbourhood's path in its fourth frame.
constexpr float kDenoiseShortHistory = 3.999f;
// Frames a history counts at most (refinement averages this many still frames).
constexpr float kDenoiseMaxHistory = 65535.0f;

// A demodulated colour and the variance of its luminance.
struct alignas(16) ColourVariance {
  Vec3 colour{0, 0, 0};
  float variance = 0.0f;
};

// What the filter compares between two pixels: the surface's normal (zero: none known) and
// 1 / view depth (0: nothing hit).
struct alignas(16) DenoiseGuide {
  Vec3 normal{0, 0, 0};
  float inverseDepth = 0.0f;
};

// Per-pixel inputs of one eye, as the eye pass wrote them (null: not available).
struct DenoiseInputs {
  const Vec3* image = nullptr;          ///< the rendered radiance
  const Vec3* emitted = nullptr;        ///< its emitted part (with direct; null: none)
  const Vec3* direct = nullptr;         ///< its direct part (emitted included); null: all of it is one signal
  const Vec3* albedo = nullptr;         ///< the demodulation albedo; null: 1
  const Vec3* normal = nullptr;         ///< the gather surface's normal; null: no normal test
  const float* inverseDepth = nullptr;  ///< required
  const float* sampleSpacing = nullptr; ///< foveated; null: 1
  // The right eye under stereo reuse: per pixel the left pixel it reused (kNotReused: none), and
  // the left eye's normals (the reused surface's guide) and denoised image there.
  const uint32_t* reusedFrom = nullptr;
  const Vec3* sourceNormal = nullptr;
  const Vec3* sourceDenoised = nullptr;
  // The left eye under stereo reuse: the right eye will read its filter's levels, so each level
  // keeps a buffer of its own (else levels two apart share one).
  bool keepLevels = false;
};

// The filter's levels per signal: level 0 is the accumulated signal with its variance, level k + 1
// the output of a-trous pass k (the last pass's output is only remodulated, not kept).
constexpr int kDenoiseLevels = kMaxDenoiseIterations + 1;

// What the left eye's denoise of this frame leaves for the right eye under stereo reuse: its new
// history's length and every filter level, so that a reused right pixel is denoised once, in the
// left eye, and a right pixel beside it filters with the left eye's values there.
struct DenoiseSharedView {
  const float* moments = nullptr;
  const float* length = nullptr;
  const ColourVariance* levels[2][kDenoiseLevels] = {};
  // Under quarterPhotonPasses the left eye's photon-map levels after the first exist at its even
  // pixels only: a reused tap there reads the nearest even pixel on the source's surface (its
  // guides tell), or else level 1 (the first pass's output, at every pixel).
  bool quarterPhotonPasses = false;
  const DenoiseGuide* guide = nullptr;
};

// One eye's denoising history: the filtered colours, moments, history length and guides of its
// last frame.
struct DenoiseHistoryView {
  EyeCamera camera;
  const ColourVariance* colour[2] = {nullptr, nullptr};  ///< direct, photon map
  const float* moments = nullptr;                        ///< 4 per pixel: each signal's luminance mean and variance
  const float* length = nullptr;                         ///< frames accumulated
  const DenoiseGuide* guide = nullptr;
  // A right eye that reused pixels last frame: their colours, moments and length are the left
  // eye's history of that frame at the pixel reused (referred to, not copied: a reused pixel's
  // accumulation writes one index instead of copying 52 bytes). Per pixel the left pixel
  // (kNotReused: the eye's own), and the left eye's history.
  const uint32_t* reusedFrom = nullptr;
  const ColourVariance* sourceColour[2] = {nullptr, nullptr};
  const float* sourceMoments = nullptr;
  const float* sourceLength = nullptr;
  PVR_HOST_DEVICE bool valid() const { return guide != nullptr; }
};

// Where a history pixel's colours, moments and length are: the eye's own at `at`, or the left
// eye's at the pixel it reused. An index and a flag, not the four pointers: the accumulation's
// four taps held those live and took 80 registers (236 us an eye on Sponza, H100, against 199 at
// 64); the pointers are picked from the view at each read.
struct HistoryTap {
  uint32_t at;
  bool left;
  PVR_HOST_DEVICE const ColourVariance& colour(const DenoiseHistoryView& h, int s) const {
    return (left ? h.sourceColour[s] : h.colour[s])[at];
  }
  PVR_HOST_DEVICE const float* moments(const DenoiseHistoryView& h) const { return left ? h.sourceMoments : h.moments; }
  PVR_HOST_DEVICE float length(const DenoiseHistoryView& h) const { return (left ? h.sourceLength : h.length)[at]; }
};
PVR_HOST_DEVICE inline HistoryTap historyTap(const DenoiseHistoryView& h, size_t at) {
  const uint32_t source = h.reusedFrom ? h.reusedFrom[at] : kNotReused;
  if (source == kNotReused) return {uint32_t(at), false};
  return {source, true};
}

// One frame's working buffers of one eye (all the eye's size).
struct DenoiseFrameView {
  EyeCamera camera;
  DenoiseInputs in;
  DenoiseParams params;
  int stillFrames = 0;  ///< frames the view has been still before this one (0: moving; refinement)
  DenoiseHistoryView history;
  DenoiseGuide* guide = nullptr;                   ///< becomes the history's
  float* moments = nullptr;                        ///< becomes the history's
  float* length = nullptr;                         ///< becomes the history's
  float* depthGradient = nullptr;                  ///< 2 per pixel: the inverse depth's gradient (x, y), per pixel
  // Per signal and level (kDenoiseLevels); a backend may let levels two apart share a buffer
  // (ping-pong) unless a reusing right eye reads them.
  ColourVariance* levels[2][kDenoiseLevels] = {};
  ColourVariance* historyOut[2] = {nullptr, nullptr};  ///< the first pass's output: the next frame's history
  uint32_t* historyReusedFrom = nullptr;  ///< a reusing right eye: the next history's reusedFrom
  Vec3* out = nullptr;                             ///< the denoised image
  DenoiseSharedView source;                        ///< the left eye's, where in.reusedFrom is set
  bool quarterPhotonPasses = false;                ///< runsQuarterPhotonPasses(params, in)
  PVR_HOST_DEVICE int twoSignals() const { return in.direct ? 2 : 1; }
};

// Whether an eye runs the photon-map signal's passes after the first on its even pixels
// (DenoiseParams::quarterPhotonPasses): a signal of its own (the direct one filtered apart) and
// taps a pixel apart. A foveated eye's steps follow its samples' spacing, whose lattice is not
// the pixels'; it filters as without.
PVR_HOST_DEVICE inline bool runsQuarterPhotonPasses(const DenoiseParams& params, const DenoiseInputs& in) {
  return params.quarterPhotonPasses && params.iterations >= 2 && in.direct != nullptr && in.sampleSpacing == nullptr;
}

// Which pixels an a-trous pass runs over: all, or under quarter photon passes the even ones
// (x and y even) and then the others.
enum class AtrousPixels { All, Even, Odd };
PVR_HOST_DEVICE inline bool evenPixel(int x, int y) { return ((x | y) & 1) == 0; }
PVR_HOST_DEVICE inline bool atrousRunsAt(AtrousPixels pixels, int x, int y) {
  return pixels == AtrousPixels::All || (pixels == AtrousPixels::Even) == evenPixel(x, y);
}

// A pixel's index in an eye's buffers (32 bits: an eye holds fewer than 2^32 pixels, and the
// a-trous pass's taps keep one register per index instead of two).
PVR_HOST_DEVICE inline uint32_t denoisePixel(const EyeCamera& c, int x, int y) { return uint32_t(y) * uint32_t(c.width) + uint32_t(x); }

// Pixel `at`'s four luminance moments (each signal's mean and variance), read and written whole:
// one 16-byte access on the GPU (the buffers hold 4 floats a pixel from an aligned start), where
// two 4-byte reads of a warp's pixels move the same cache sectors twice.
struct Moments {
  float m[4];
};
PVR_HOST_DEVICE inline Moments loadMoments(const float* moments, size_t at) {
#ifdef __CUDA_ARCH__
  const float4 v = *reinterpret_cast<const float4*>(moments + 4 * at);
  return {{v.x, v.y, v.z, v.w}};
#else
  return {{moments[4 * at], moments[4 * at + 1], moments[4 * at + 2], moments[4 * at + 3]}};
#endif
}
PVR_HOST_DEVICE inline void storeMoments(float* moments, size_t at, const Moments& m) {
#ifdef __CUDA_ARCH__
  *reinterpret_cast<float4*>(moments + 4 * at) = make_float4(m.m[0], m.m[1], m.m[2], m.m[3]);
#else
  for (int k = 0; k < 4; ++k) moments[4 * at + k] = m.m[k];
#endif
}

// The filter's exponentials and logarithms: the GPU's fast intrinsics (a few ulp from the host's,
// far below what the weights need).
PVR_HOST_DEVICE inline float filterExp(float x) {
#ifdef __CUDA_ARCH__
  return __expf(x);
#else
  return expf(x);
#endif
}
PVR_HOST_DEVICE inline float filterDivide(float a, float b) {
#ifdef __CUDA_ARCH__
  return __fdividef(a, b);
#else
  return a / b;
#endif
}
PVR_HOST_DEVICE inline float filterRsqrt(float x) {
#ifdef __CUDA_ARCH__
  return rsqrtf(x);
#else
  return 1.0f / sqrtf(x);
#endif
}

// A pixel's local sample spacing as an integer step (1 at full resolution).
PVR_HOST_DEVICE inline int denoiseSpacing(const DenoiseFrameView& v, size_t pixel) {
  if (!v.in.sampleSpacing) return 1;
  float s = v.in.sampleSpacing[pixel];
  return s > 1.5f ? int(s + 0.5f) : 1;
}

// Divides by the albedo where it can be divided by (a black or non-finite channel keeps its value).
PVR_HOST_DEVICE inline Vec3 demodulationAlbedo(Vec3 a) {
  const float kMin = 1e-3f, kMax = 1e30f;
  auto channel = [&](float c) { return c > kMin && c < kMax ? c : 1.0f; };
  return {channel(a.x), channel(a.y), channel(a.z)};
}
PVR_HOST_DEVICE inline Vec3 divide(Vec3 a, Vec3 b) { return {a.x / b.x, a.y / b.y, a.z / b.z}; }

// Whether two guides may be the same surface, and if so how unlike they are: `penalty` is the
// exponent of their weight, exp(-penalty). `dx`, `dy` are q's offset from p in pixels and (gx, gy)
// p's inverse-depth gradient: inverse depth is affine across a plane in screen space, so q is
// compared with p's plane extended to it. (The penalties of depth, normal and luminance add up,
// so that a tap costs one exponential per signal.)
PVR_HOST_DEVICE inline bool sameSurface(const DenoiseGuide& p, const DenoiseGuide& q, float gx, float gy, float dx,
                                        float dy, const DenoiseParams& params, float& penalty) {
  penalty = 0.0f;
  if ((p.inverseDepth > 0.0f) != (q.inverseDepth > 0.0f)) return false;  // background never meets a surface
  if (p.inverseDepth > 0.0f) {
    const float predicted = p.inverseDepth + gx * dx + gy * dy;
    const float difference = fabsf(q.inverseDepth - predicted);
    const float tolerance = params.depthTolerance * fmaxf(p.inverseDepth, q.inverseDepth);
    if (!(difference <= tolerance)) return false;
    penalty = filterDivide(difference, tolerance);
  }
  const bool pHas = !isBlack(p.normal), qHas = !isBlack(q.normal);
  if (pHas != qHas) return false;
  if (pHas) {
    const float c = dot(p.normal, q.normal);
    if (!(c >= kDenoiseMinNormalCosine)) return false;
    // exp(-power (1 - cos)): within a few per cent of cos^power above the cut, without a logarithm.
    penalty += params.normalPower * fmaxf(0.0f, 1.0f - c);
  }
  return true;
}

// The same as a weight in [0, 1] (0: never blend).
PVR_HOST_DEVICE inline float geometryWeight(const DenoiseGuide& p, const DenoiseGuide& q, float gx, float gy, float dx,
                                            float dy, const DenoiseParams& params) {
  float penalty;
  return sameSurface(p, q, gx, gy, dx, dy, params, penalty) ? filterExp(-penalty) : 0.0f;
}

// The inverse-depth gradient at pixel (x, y), per pixel: the smaller one-sided difference on
// each axis among neighbours on the same side of any edge (zero where neither is).
PVR_HOST_DEVICE inline void inverseDepthGradient(const float* inverseDepth, const EyeCamera& c, int x, int y, int step,
                                                 float& gx, float& gy) {
  const float centre = inverseDepth[denoisePixel(c, x, y)];
  auto axis = [&](int ax, int ay) {
    float best = 0.0f;
    bool found = false;
    for (int side = -1; side <= 1; side += 2) {
      const int qx = x + side * ax * step, qy = y + side * ay * step;
      if (qx < 0 || qy < 0 || qx >= c.width || qy >= c.height) continue;
      const float g = (inverseDepth[denoisePixel(c, qx, qy)] - centre) * float(side) / float(step);
      if (!found || fabsf(g) < fabsf(best)) best = g, found = true;
    }
    return found && fabsf(best) <= 0.5f * centre ? best : 0.0f;  // a jump is an edge, not a slope
  };
  gx = centre > 0.0f ? axis(1, 0) : 0.0f;
  gy = centre > 0.0f ? axis(0, 1) : 0.0f;
}

// The left pixel a right pixel reused under stereo reuse (kNotReused: none, or not the reusing eye).
PVR_HOST_DEVICE inline uint32_t reusedSourcePixel(const DenoiseFrameView& v, size_t pixel) {
  return v.in.reusedFrom ? v.in.reusedFrom[pixel] : kNotReused;
}

// Whether the eye filters the pixel (steps 3-5): it sees a surface, and one of its own. Background
// has nothing to filter (it shows what the eye pass rendered: the sky or black); a reused right
// pixel shares the left eye's denoise.
PVR_HOST_DEVICE inline bool filtersPixel(const DenoiseFrameView& v, size_t pixel) {
  return v.in.inverseDepth[pixel] > 0.0f && reusedSourcePixel(v, pixel) == kNotReused;
}

// Whether a history pixel whose guide is `g` saw the surface a pixel with `guide` reprojects onto
// (inverse depth `expected` there).
PVR_HOST_DEVICE inline bool sameHistoryGuide(const DenoiseGuide& g, float expected, const DenoiseGuide& guide,
                                             const DenoiseParams& params) {
  if ((g.inverseDepth > 0.0f) != (expected > 0.0f)) return false;
  if (expected > 0.0f && !(fabsf(g.inverseDepth - expected) <= params.depthTolerance * fmaxf(g.inverseDepth, expected)))
    return false;
  if (isBlack(g.normal) != isBlack(guide.normal)) return false;
  return isBlack(guide.normal) || dot(g.normal, guide.normal) >= kDenoiseMinNormalCosine;
}

// The a-trous passes signal s takes. The photon-map signal (and a lone signal) takes every pass:
// its noise is blotches as wide as the search radius. The direct signal's noise is a shadow ray's
// per pixel, fine-grained (blue-noise dithered), and the first directIterations passes (at least
// one: the first pass's output is the history) may do for it.
PVR_HOST_DEVICE inline int denoisePasses(const DenoiseParams& params, int signals, int s) {
  if (signals < 2 || s == 1) return params.iterations;
  const int direct = params.directIterations < 1 ? 1 : params.directIterations;
  return direct < params.iterations ? direct : params.iterations;
}

// What one a-trous pass reads and writes, per signal it filters (its first `signals` slots, in
// signal order): the eye's own level, the left eye's same level for reused right pixels, and the
// next level (none for the last pass, which remodulates). A signal whose passes ended earlier is
// only added in at the last pass (`finished`, its last level).
//
// Under quarter photon passes (pass 1 on, `pixels` Even or Odd) the photon-map signal is a slot of
// the even pixels' passes only, whose last pass also keeps its output as level `iterations`; the
// odd pixels' last pass interpolates that (`upsampled`; `fallback`, level 1, the first pass's
// output, where no even neighbour shares its surface: the later passes write only even pixels, so
// it is there at the odd ones also when levels two apart share a buffer). A reusing right eye
// reads the left eye's photon-map levels from pass 2 on, and its last, at the nearest even pixel
// (`sourceLatticeSlot`; else its level 1, `sourceFallback`).
struct AtrousLevels {
  int signals = 0;
  const ColourVariance* in[2] = {nullptr, nullptr};
  const ColourVariance* sourceIn[2] = {nullptr, nullptr};
  ColourVariance* out[2] = {nullptr, nullptr};
  const ColourVariance* finished = nullptr;
  int sourceLatticeSlot = -1;
  const ColourVariance* upsampled = nullptr;
  const ColourVariance* sourceUpsampled = nullptr;
  const ColourVariance* fallback = nullptr;
  const ColourVariance* sourceFallback = nullptr;
  // Whether the pass has anything to do at its pixels (an odd pixel's middle pass under quarter
  // photon passes, the direct signal's passes over, has not).
  PVR_HOST_DEVICE bool runs() const { return signals > 0 || upsampled != nullptr; }
};
PVR_HOST_DEVICE inline AtrousLevels atrousLevels(const DenoiseFrameView& v, int iteration,
                                                 AtrousPixels pixels = AtrousPixels::All) {
  AtrousLevels l;
  const int signals = v.twoSignals();
  const int iterations = v.params.iterations;
  const bool last = iteration + 1 >= iterations;
  for (int s = 0; s < signals; ++s) {
    const int passes = denoisePasses(v.params, signals, s);
    if (iteration >= passes) {
      if (last) l.finished = v.levels[s][passes];
      continue;
    }
    const bool lattice = pixels != AtrousPixels::All && s == 1;  // the photon-map signal, on the even pixels
    if (lattice && pixels == AtrousPixels::Odd) {
      if (last) {
        l.upsampled = v.levels[1][iterations];
        l.sourceUpsampled = v.source.levels[1][iterations];
        l.fallback = v.levels[1][1];
        l.sourceFallback = v.source.levels[1][1];
      }
      continue;
    }
    l.in[l.signals] = v.levels[s][iteration];
    l.sourceIn[l.signals] = v.source.levels[s][iteration];
    if (!last) l.out[l.signals] = v.levels[s][iteration + 1];
    else if (lattice) l.out[l.signals] = v.levels[1][iterations];
    if (s == 1 && v.source.quarterPhotonPasses && iteration >= 2) {
      l.sourceLatticeSlot = l.signals;
      l.sourceFallback = v.source.levels[1][1];
    }
    ++l.signals;
  }
  return l;
}

// Visits the even pixels beside pixel (x, y) inside the image (the two on its row or column, or its
// four diagonal ones) until `visit(ex, ey)` returns true; returns whether one did.
template <class Visit>
PVR_HOST_DEVICE inline bool forEachEvenNeighbour(const EyeCamera& c, int x, int y, const Visit& visit) {
  const int nx = x & 1 ? 2 : 1, ny = y & 1 ? 2 : 1;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int ex = (x & ~1) + 2 * i, ey = (y & ~1) + 2 * j;
      if (ex < c.width && ey < c.height && visit(ex, ey)) return true;
    }
  return false;
}

// The even pixel of the left eye whose photon-map levels stand for its pixel `source` under
// quarter photon passes: the pixel itself if even, else the first of its even neighbours (2 or 4)
// on the same surface; false where none is.
PVR_HOST_DEVICE inline bool latticeSourcePixel(const DenoiseFrameView& v, uint32_t source, uint32_t& at) {
  const int sx = int(source % uint32_t(v.camera.width)), sy = int(source / uint32_t(v.camera.width));
  if (evenPixel(sx, sy)) {
    at = source;
    return true;
  }
  const DenoiseGuide g = v.source.guide[source];
  return forEachEvenNeighbour(v.camera, sx, sy, [&](int ex, int ey) {
    const uint32_t e = denoisePixel(v.camera, ex, ey);
    if (!sameHistoryGuide(v.source.guide[e], g.inverseDepth, g, v.params)) return false;
    at = e;
    return true;
  });
}

// Signal s of pixel q at the pass's input level: the eye's own, or for a reused right pixel the
// left eye's at the pixel it reused.
PVR_HOST_DEVICE inline const ColourVariance& levelAt(const DenoiseFrameView& v, const AtrousLevels& l, int s, size_t q) {
  const uint32_t source = reusedSourcePixel(v, q);
  return source == kNotReused ? l.in[s][q] : l.sourceIn[s][source];
}
// The same under quarter photon passes, where the left eye may have the level at its even pixels
// only: at the nearest one on that surface, else its level 1 there.
PVR_HOST_DEVICE inline ColourVariance quarterLevelAt(const DenoiseFrameView& v, const AtrousLevels& l, int s, size_t q) {
  const uint32_t source = reusedSourcePixel(v, q);
  if (source == kNotReused) return l.in[s][q];
  // One load at the end from a chosen level and pixel (choosing between two references made the
  // GPU keep the levels in a stack frame).
  const ColourVariance* level = l.sourceIn[s];
  uint32_t at = source;
  if (s == l.sourceLatticeSlot && !latticeSourcePixel(v, source, at)) level = l.sourceFallback, at = source;
  return level[at];
}

// The pixel's inputs: demodulated signals, albedo and guide.
PVR_HOST_DEVICE inline void demodulatedInputs(const DenoiseFrameView& v, size_t pixel, Vec3 signal[2], Vec3& albedo,
                                              DenoiseGuide& guide) {
  const DenoiseInputs& in = v.in;
  const Vec3 image = in.image[pixel];
  albedo = in.albedo ? demodulationAlbedo(in.albedo[pixel]) : Vec3(1.0f);
  if (in.direct) {
    const Vec3 d = in.direct[pixel], e = in.emitted ? in.emitted[pixel] : Vec3(0.0f);
    signal[0] = divide(max(d - e, Vec3(0.0f)), albedo);
    signal[1] = divide(max(image - d, Vec3(0.0f)), albedo);
  } else {
    signal[0] = divide(image, albedo);
    signal[1] = Vec3(0.0f);
  }
  // A sample still not finite here (+Inf passes the clamps above, as NaN does with one signal)
  // counts as black, as pbrt's film drops one: else the filter spreads it over its footprint and a
  // refining history keeps it.
  for (int s = 0; s < 2; ++s)
    if (!isFinite(signal[s])) signal[s] = Vec3(0.0f);
  guide.normal = in.normal ? in.normal[pixel] : Vec3(0.0f);
  guide.inverseDepth = in.inverseDepth[pixel];
}

// The history's colours and luminance means at fraction (tx, ty) past pixel (x0, y0) by
// Catmull-Rom over the 4x4 pixels around without its corners (each corner's weight, a product of
// the two negative lobes, is below 0.6 %; the other 12 are renormalised), each clamped to the
// range of the 2x2 pixels nearest (no ringing); false (and the outputs unfinished) where one of
// the 12 saw another surface or lies outside the image.
template <int S>
PVR_HOST_DEVICE inline bool catmullRomHistory(const DenoiseHistoryView& h, int x0, int y0, float tx, float ty,
                                              float expected, const DenoiseGuide& guide, const DenoiseParams& params,
                                              Vec3 colour[2], float mean[2]) {
  if (x0 < 1 || y0 < 1 || x0 + 2 >= h.camera.width || y0 + 2 >= h.camera.height) return false;
  float wx[4], wy[4];
  catmullRomWeights(tx, wx);
  catmullRomWeights(ty, wy);
  // Every tap is read and summed whatever its guide says, and the guides' verdict is taken at the
  // end, so that no tap's loads wait for another tap's test. The read is bound by the cache's
  // bandwidth (16 taps of guide, colours and moments: 373 us an eye on Sponza against bilinear's
  // 206, H100), hence 12 taps and the moments in one load.
  bool same = true;
  float total = 0.0f;
#ifdef __CUDA_ARCH__
#pragma unroll
#endif
  for (int j = 0; j < 4; ++j)
#ifdef __CUDA_ARCH__
#pragma unroll
#endif
    for (int i = 0; i < 4; ++i) {
      if ((i == 0 || i == 3) && (j == 0 || j == 3)) continue;  // a corner
      const size_t at = denoisePixel(h.camera, x0 - 1 + i, y0 - 1 + j);
      same &= sameHistoryGuide(h.guide[at], expected, guide, params);
      const HistoryTap t = historyTap(h, at);
      const Moments m = loadMoments(t.moments(h), t.at);
      const float w = wx[i] * wy[j];
      for (int s = 0; s < S; ++s) {
        colour[s] += t.colour(h, s).colour * w;
        mean[s] += m.m[2 * s] * w;
      }
      total += w;
    }
  if (!same) return false;
  // The clamp, a signal at a time over the 2x2 nearest (read again: cached, and fewer registers
  // held through the taps above on the GPU).
  const size_t at = denoisePixel(h.camera, x0, y0);
  HistoryTap t[4];
  Moments m[4];
  for (int k = 0; k < 4; ++k) {
    t[k] = historyTap(h, at + size_t(k & 1) + size_t(k >> 1) * size_t(h.camera.width));
    m[k] = loadMoments(t[k].moments(h), t[k].at);
  }
  for (int s = 0; s < S; ++s) {
    Vec3 lowest = t[0].colour(h, s).colour, highest = lowest;
    float lowestMean = m[0].m[2 * s], highestMean = lowestMean;
    for (int k = 1; k < 4; ++k) {
      const Vec3 c = t[k].colour(h, s).colour;
      lowest = min(lowest, c), highest = max(highest, c);
      lowestMean = fminf(lowestMean, m[k].m[2 * s]), highestMean = fmaxf(highestMean, m[k].m[2 * s]);
    }
    colour[s] = min(max(colour[s] / total, lowest), highest);
    mean[s] = fminf(fmaxf(mean[s] / total, lowestMean), highestMean);
  }
  return true;
}

// Step 2 for a pixel the eye does not filter. A reused right pixel's history is the left eye's
// new history at the pixel it reused (referred to by historyReusedFrom: it carries that history
// on if it is shaded by its own eye next frame), and it shows the left eye's denoised colour
// there: one denoise of that surface, and both eyes agree on it. Background shows the rendered
// image and keeps no history (only its guide, which no surface's reprojection or neighbourhood
// accepts).
template <int S>
PVR_HOST_DEVICE inline bool accumulateUnfilteredPixel(const DenoiseFrameView& v, size_t pixel) {
  const uint32_t source = reusedSourcePixel(v, pixel);
  DenoiseGuide guide;
  guide.inverseDepth = v.in.inverseDepth[pixel];
  if (v.historyReusedFrom) v.historyReusedFrom[pixel] = source;
  if (source != kNotReused) {
    guide.normal = v.in.sourceNormal ? v.in.sourceNormal[source] : Vec3(0.0f);
    v.guide[pixel] = guide;
    v.out[pixel] = v.in.sourceDenoised[source];
    return v.source.length[source] > 1.5f;
  }
  // Background: its guide turns away every later read of its history (no surface meets it).
  v.guide[pixel] = guide;
  v.out[pixel] = v.in.image[pixel];
  return false;
}

// Step 2 at pixel (x, y): the accumulated signals (variance from the moments) into level 0,
// moments, history length and the pixel's guide. Returns whether the history
// contributed (for a reused right pixel: whether the left eye's had).
// Each pass is written for S signals (1 or 2) known at compile time, so that the per-signal arrays
// stay in registers on the GPU; the untemplated names choose S from the inputs.
template <int S>
PVR_HOST_DEVICE inline bool accumulateDenoisePixelOf(const DenoiseFrameView& v, int x, int y) {
  const size_t pixel = denoisePixel(v.camera, x, y);
  if (!filtersPixel(v, pixel)) return accumulateUnfilteredPixel<S>(v, pixel);
  if (v.historyReusedFrom) v.historyReusedFrom[pixel] = kNotReused;
  Vec3 signal[2], albedo;
  DenoiseGuide guide;
  demodulatedInputs(v, pixel, signal, albedo, guide);
  v.guide[pixel] = guide;
  inverseDepthGradient(v.in.inverseDepth, v.camera, x, y, denoiseSpacing(v, pixel), v.depthGradient[2 * pixel],
                       v.depthGradient[2 * pixel + 1]);
  // Each signal's luminance: its mean and variance over the accumulated frames (kept as mean and
  // variance, not mean and mean square: a moving head resamples them, and averaging neighbours'
  // mean squares would count the spread of their means, a sharp edge or gradient of the signal,
  // as noise, so the filter would blur it by an amount that changes with the sub-pixel offset).
  float luminances[2];
  for (int s = 0; s < 2; ++s) luminances[s] = luminance(signal[s]);

  // The history's 2x2 taps around where the pixel was, those that saw this surface.
  Vec3 history[2] = {Vec3(0.0f), Vec3(0.0f)};
  float historyMoments[4] = {0, 0, 0, 0}, historyLength = 0.0f, total = 0.0f;
  const DenoiseHistoryView& h = v.history;
  if (h.valid()) {
    TaaView reprojection;
    reprojection.camera = v.camera;
    reprojection.previousCamera = h.camera;
    reprojection.inverseDepth = v.in.inverseDepth;
    float px, py, expected;
    if (reprojectToPrevious(reprojection, x, y, px, py, expected)) {
      float fx = px - 0.5f, fy = py - 0.5f;
      const float sx = floorf(fx + 0.5f), sy = floorf(fy + 0.5f);
      if (fabsf(fx - sx) < kTaaSnapPixels && fabsf(fy - sy) < kTaaSnapPixels) fx = sx, fy = sy;  // a still head
      const int x0 = int(floorf(fx)), y0 = int(floorf(fy));
      const float tx = fx - float(x0), ty = fy - float(y0);
      // Each tap's guide and colours are read before its test, from the nearest pixel inside the
      // image (a tap outside has no weight): the four taps' loads go out together.
#ifdef __CUDA_ARCH__
#pragma unroll
#endif
      for (int j = 0; j < 2; ++j)
#ifdef __CUDA_ARCH__
#pragma unroll
#endif
        for (int i = 0; i < 2; ++i) {
          const int hx = x0 + i, hy = y0 + j;
          const bool inside = hx >= 0 && hy >= 0 && hx < h.camera.width && hy < h.camera.height;
          const size_t at = denoisePixel(h.camera, hx < 0 ? 0 : hx >= h.camera.width ? h.camera.width - 1 : hx,
                                         hy < 0 ? 0 : hy >= h.camera.height ? h.camera.height - 1 : hy);
          const DenoiseGuide g = h.guide[at];
          const HistoryTap t = historyTap(h, at);
          Vec3 colours[2];
          for (int s = 0; s < S; ++s) colours[s] = t.colour(h, s).colour;
          const float w = (i ? tx : 1.0f - tx) * (j ? ty : 1.0f - ty);
          if (!(w > 0.0f) || !inside || !sameHistoryGuide(g, expected, guide, v.params)) continue;
          for (int s = 0; s < S; ++s) history[s] += colours[s] * w;
          const Moments m = loadMoments(t.moments(h), t.at);
          for (int k = 0; k < 4; ++k) historyMoments[k] += m.m[k] * w;
          historyLength += t.length(h) * w;
          total += w;
        }
      // A moving head resamples the history every frame: bilinear weights blur it by an amount
      // that changes with the sub-pixel offset, frame to frame (a flicker of its own). Asked for,
      // and where the 12 taps around the point all saw this surface, the colour and the luminance
      // mean are read by Catmull-Rom instead (sharp, exact at pixel centres). Variances and the
      // history's length stay bilinear (smooth, and never negative).
      if (v.params.bicubicHistory && total > 0.999f && (tx > 0.0f || ty > 0.0f)) {
        Vec3 bicubic[2] = {Vec3(0.0f), Vec3(0.0f)};
        float bicubicMean[2] = {0.0f, 0.0f};
        if (catmullRomHistory<S>(h, x0, y0, tx, ty, expected, guide, v.params, bicubic, bicubicMean))
          for (int s = 0; s < S; ++s) history[s] = bicubic[s] * total, historyMoments[2 * s] = bicubicMean[s] * total;
      }
    }
  }
  // The frames the accumulated average stands for: one more than the history's. A moving head
  // keeps 1 / colourAlpha of them (the exponential average's weight); a still head keeps them all
  // (refinement: a running mean; the moving head's history counts as its 1 / colourAlpha); and a
  // long refined history, once the head moves, halves each frame down to the moving head's, so the
  // refined picture fades into the moving one over a few frames instead of dropping out at once.
  const bool used = total > 0.01f;
  const bool refining = used && v.stillFrames > 0;
  const float moving = 1.0f / v.params.colourAlpha;
  float frames = used ? fminf(historyLength / total + 1.0f, kDenoiseMaxHistory) : 1.0f;
  if (refining) frames = fminf(frames, float(v.stillFrames) + moving);
  else if (frames > moving) frames = fmaxf(moving, 0.5f * frames);
  const float alpha = 1.0f / frames;
  const float alphaMoments = refining ? alpha : fmaxf(v.params.momentsAlpha, alpha);
  float variances[2];
  Moments moments;
  for (int s = 0; s < 2; ++s) {
    float mean = luminances[s], variance = 0.0f;
    if (used) {
      // An exponentially weighted mean and variance (a running one while refining).
      const float previousMean = historyMoments[2 * s] / total, difference = luminances[s] - previousMean;
      mean = previousMean + difference * alphaMoments;
      variance = (1.0f - alphaMoments) * (historyMoments[2 * s + 1] / total + alphaMoments * difference * difference);
    }
    moments.m[2 * s] = mean, moments.m[2 * s + 1] = variance;
    variances[s] = variance;
  }
  storeMoments(v.moments, pixel, moments);
  v.length[pixel] = frames;
  for (int s = 0; s < S; ++s) {
    const Vec3 previous = used ? history[s] / total : Vec3(0.0f);
    ColourVariance c;
    c.colour = previous + (signal[s] - previous) * alpha;
    c.variance = variances[s];
    // Beyond the moving head's frames the filter sees the average's variance, so it fades out as
    // that falls; a refining history is the plain average, never a filtered one.
    c.variance *= fminf(1.0f, alpha * moving);
    if (refining) v.historyOut[s][pixel] = c;  // else the first a-trous pass (or remodulate) writes it
    v.levels[s][0][pixel] = c;
  }
  return used;
}


// Step 3 at a pixel the eye filters: where the history is short, the variance of level 0 from the
// moments of a 7x7 neighbourhood on the same surface, read at every other pixel (offsets -3, -1,
// 1, 3 on each axis, and the pixel itself: 17 taps, a third of the window's 49, for the frames
// after a cut or disocclusion, when every pixel of an eye takes this path at once).
template <int S>
PVR_HOST_DEVICE inline void estimateDenoiseVarianceOf(const DenoiseFrameView& v, int x, int y) {
  const size_t pixel = denoisePixel(v.camera, x, y);
  if (!(v.length[pixel] < kDenoiseShortHistory)) return;
  const DenoiseGuide p = v.guide[pixel];
  const int step = denoiseSpacing(v, pixel);
  const float gx = v.depthGradient[2 * pixel], gy = v.depthGradient[2 * pixel + 1];
  // The window's luminance mean and mean square (each pixel's variance plus its squared mean).
  float sum[4], total = 1.0f;
  auto add = [&](size_t q, float w) {
    // A reused right pixel's moments are the left eye's (this frame's, at the pixel reused).
    const uint32_t source = reusedSourcePixel(v, q);
    const Moments m = source == kNotReused ? loadMoments(v.moments, q) : loadMoments(v.source.moments, source);
    for (int s = 0; s < 2; ++s) {
      const float mean = m.m[2 * s];
      sum[2 * s] += mean * w;
      sum[2 * s + 1] += (m.m[2 * s + 1] + mean * mean) * w;
    }
  };
  for (int m = 0; m < 4; ++m) sum[m] = 0.0f;
  add(pixel, 1.0f);
  for (int j = -3; j <= 3; j += 2)
    for (int i = -3; i <= 3; i += 2) {
      const int qx = x + i * step, qy = y + j * step;
      if (qx < 0 || qy < 0 || qx >= v.camera.width || qy >= v.camera.height) continue;
      const size_t q = denoisePixel(v.camera, qx, qy);
      const float w = geometryWeight(p, v.guide[q], gx, gy, float(i * step), float(j * step), v.params);
      if (!(w > 0.0f)) continue;
      add(q, w);
      total += w;
    }
  for (int s = 0; s < S; ++s) {
    const float mean = sum[2 * s] / total, meanSquare = sum[2 * s + 1] / total;
    v.levels[s][0][pixel].variance = fmaxf(0.0f, meanSquare - mean * mean);
  }
}

// The denoised colour of a pixel the eye filters: its filtered signals remodulated.
PVR_HOST_DEVICE inline void writeDenoised(const DenoiseFrameView& v, size_t pixel, Vec3 demodulated) {
  const Vec3 emitted = v.in.direct && v.in.emitted ? v.in.emitted[pixel] : Vec3(0.0f);
  // The albedo demodulated by, read again rather than kept: a pixel's buffer less to write.
  const Vec3 albedo = v.in.albedo ? demodulationAlbedo(v.in.albedo[pixel]) : Vec3(1.0f);
  v.out[pixel] = emitted + demodulated * albedo;
}

// Whether the pixel is refining this frame: the view is still and the pixel kept its history.
PVR_HOST_DEVICE inline bool refiningPixel(const DenoiseFrameView& v, size_t pixel) {
  return v.stillFrames > 0 && v.length[pixel] > 1.5f;
}

// The a-trous taps' 1D weights at offsets -1..1 (a 3x3 kernel: each pass doubles the step, so five
// passes reach 31 samples across at a third of a 5x5 kernel's taps).
PVR_HOST_DEVICE inline float atrousKernel(int i) { return i == 0 ? 0.5f : 0.25f; }

// Where an a-trous pass reads the pixel's 3x3 taps (offsets (i, j) in -1..1 of its step; q the
// tap's pixel): the eye's buffers, as here (the CPU, and the GPU's listed pixels), or a GPU
// block's tile of them in shared memory (cuda/denoise.cu).
// Under quarter photon passes (the passes after the first) QuarterMemoryTaps: a reused tap may read
// the left eye's nearest even pixel, and the odd pixels' last pass adds their interpolated
// photon-map signal. Apart, so that the full filter's kernels carry none of it (on the GPU the
// branches cost the list kernel 8 registers and a stack frame).
template <bool QuarterPhotonPasses>
struct MemoryTapsOf {
  static constexpr bool kQuarterPhotonPasses = QuarterPhotonPasses;
  const DenoiseFrameView& v;
  const AtrousLevels& l;
  PVR_HOST_DEVICE DenoiseGuide guide(int, int, size_t q) const { return v.guide[q]; }
  PVR_HOST_DEVICE ColourVariance value(int s, int, int, size_t q) const {
    if constexpr (QuarterPhotonPasses) return quarterLevelAt(v, l, s, q);
    else return levelAt(v, l, s, q);
  }
};
using MemoryTaps = MemoryTapsOf<false>;
using QuarterMemoryTaps = MemoryTapsOf<true>;

// A 3x3 Gaussian of level 0's variance of signal s around the pixel over its own surface (the
// luminance test's scale, less noisy; a noisier surface beside it does not loosen it). Its taps are
// the first pass's.
template <class Taps>
PVR_HOST_DEVICE inline float blurredVariance(const DenoiseFrameView& v, const Taps& taps, int s, const DenoiseGuide& p,
                                             float gx, float gy, int x, int y, int step) {
  float sum = 0.0f, total = 0.0f;
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i) {
      const int qx = x + i * step, qy = y + j * step;
      if (qx < 0 || qy < 0 || qx >= v.camera.width || qy >= v.camera.height) continue;
      const size_t q = denoisePixel(v.camera, qx, qy);
      float penalty;
      if ((i || j) && !sameSurface(p, taps.guide(i, j, q), gx, gy, float(i * step), float(j * step), v.params, penalty))
        continue;
      const float w = (i == 0 ? 0.5f : 0.25f) * (j == 0 ? 0.5f : 0.25f);
      sum += taps.value(s, i, j, q).variance * w;
      total += w;
    }
  return sum / total;
}

// The photon-map signal of an odd pixel after its last pass under quarter photon passes: the mean
// of its even neighbours' (the pixels beside it on its row or column, or its four diagonal ones)
// last-pass outputs, each weighed by the passes' own tests: the depth plane and normal, so no
// other surface's light comes in, and the luminance against the pixel's first-pass output, scaled
// by the larger standard deviation (noisy: the plain mean; converged: a step in the signal stays
// sharp). Where none is left (a feature a pixel wide, or a step), its own first-pass output.
PVR_HOST_DEVICE inline Vec3 upsampledPhotonMap(const DenoiseFrameView& v, const AtrousLevels& l, int x, int y) {
  const size_t pixel = denoisePixel(v.camera, x, y);
  const DenoiseGuide p = v.guide[pixel];
  const ColourVariance own = l.fallback[pixel];
  const float lp = luminance(own.colour);
  const float sigma2 = v.params.sigmaLuminance * v.params.sigmaLuminance;
  const float gx = v.depthGradient[2 * pixel], gy = v.depthGradient[2 * pixel + 1];
  Vec3 sum(0.0f);
  float total = 0.0f;
  forEachEvenNeighbour(v.camera, x, y, [&](int ex, int ey) {
    const size_t e = denoisePixel(v.camera, ex, ey);
    float penalty;
    if (!sameSurface(p, v.guide[e], gx, gy, float(ex - x), float(ey - y), v.params, penalty)) return false;
    // A reused right pixel's value is the left eye's, at the even pixel standing for it.
    const uint32_t source = reusedSourcePixel(v, e);
    uint32_t at = 0;
    const ColourVariance c = source == kNotReused                 ? l.upsampled[e]
                             : latticeSourcePixel(v, source, at) ? l.sourceUpsampled[at]
                                                                 : l.sourceFallback[source];
    const float inverseScale = filterRsqrt(sigma2 * fmaxf(own.variance, c.variance) + 1e-12f);
    const float w = filterExp(-penalty - fabsf(luminance(c.colour) - lp) * inverseScale);
    sum += c.colour * w;
    total += w;
    return false;  // every neighbour
  });
  // (Weights that the tests all but refuse, down to denormals, count as refused.)
  return total > 1e-6f ? sum / total : own.colour;
}

// Step 4, a-trous pass `iteration` at a pixel the eye filters: reads level `iteration`, writes the
// next (and the history after the first pass); the last pass remodulates into `out`. `l` is
// atrousLevels(v, iteration, the pixels the pass runs over); `taps` reads the level's values
// (MemoryTaps, or a GPU tile).
template <int S, class Taps>
PVR_HOST_DEVICE inline void atrousDenoisePixelOf(const DenoiseFrameView& v, int iteration, const AtrousLevels& l,
                                                 const Taps& taps, int x, int y) {
  const size_t pixel = denoisePixel(v.camera, x, y);
  constexpr int signals = S;
  const DenoiseGuide p = taps.guide(0, 0, pixel);
  const int spacing = denoiseSpacing(v, pixel);
  const int step = spacing << iteration;
  const float gx = v.depthGradient[2 * pixel], gy = v.depthGradient[2 * pixel + 1];
  // The pixel's own tap first (kernel weight 1/2 x 1/2); then only its luminance and the
  // variance that scales the luminance test are needed.
  const float centreKernel = atrousKernel(0) * atrousKernel(0);
  Vec3 sum[2];
  float variance[2], total[2], lp[2], centreVariance[2];
#ifdef __CUDA_ARCH__
#pragma unroll
#endif
  for (int s = 0; s < signals; ++s) {
    const ColourVariance centre = taps.value(s, 0, 0, pixel);
    sum[s] = centre.colour * centreKernel;
    variance[s] = centre.variance * centreKernel * centreKernel;
    total[s] = centreKernel;
    lp[s] = luminance(centre.colour);
    // The first pass's variance is the noisy estimate of one frame's moments: blurred over the
    // surface first. The later passes' have been filtered by the earlier passes already.
    centreVariance[s] = iteration == 0 ? blurredVariance(v, taps, s, p, gx, gy, x, y, spacing) : centre.variance;
  }
  const float sigma2 = v.params.sigmaLuminance * v.params.sigmaLuminance;
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i) {
      if (i == 0 && j == 0) continue;
      const int qx = x + i * step, qy = y + j * step;
      if (qx < 0 || qy < 0 || qx >= v.camera.width || qy >= v.camera.height) continue;
      const size_t q = denoisePixel(v.camera, qx, qy);
      // The tap's guide and values are read together, before the guide is tested: one trip to
      // memory per tap, not two (a rejected tap's values are read and left unused).
      const DenoiseGuide g = taps.guide(i, j, q);
      ColourVariance values[2];
#ifdef __CUDA_ARCH__
#pragma unroll
#endif
      for (int s = 0; s < signals; ++s) values[s] = taps.value(s, i, j, q);
      float geometry = 0.0f;
      if (!sameSurface(p, g, gx, gy, float(i * step), float(j * step), v.params, geometry)) continue;
      const float kernel = atrousKernel(i) * atrousKernel(j);
#ifdef __CUDA_ARCH__
#pragma unroll
#endif
      for (int s = 0; s < signals; ++s) {
        const ColourVariance& c = values[s];
        // The larger of the two variances scales the luminance test, so that two pixels weigh each
        // other alike: a dark pixel whose few samples happened to agree (a small variance) still
        // takes its bright neighbours' light, as they take its darkness, and the mean stays.
        const float inverseScale = filterRsqrt(sigma2 * fmaxf(centreVariance[s], c.variance) + 1e-12f);
        const float w = kernel * filterExp(-geometry - fabsf(luminance(c.colour) - lp[s]) * inverseScale);
        sum[s] += c.colour * w;
        variance[s] += c.variance * w * w;
        total[s] += w;
      }
    }
  ColourVariance result[2];
#ifdef __CUDA_ARCH__
#pragma unroll
#endif
  for (int s = 0; s < signals; ++s) {
    result[s].colour = sum[s] / total[s];
    result[s].variance = variance[s] / (total[s] * total[s]);
    if (l.out[s]) l.out[s][pixel] = result[s];
    // (The first pass filters every signal: its slots are the signals.)
    if (iteration == 0 && !refiningPixel(v, pixel)) v.historyOut[s][pixel] = result[s];
  }
  if (iteration == v.params.iterations - 1) {
    Vec3 radiance = result[0].colour;
    if (signals == 2) radiance += result[signals - 1].colour;
    if (l.finished) radiance += l.finished[pixel].colour;
    if constexpr (Taps::kQuarterPhotonPasses)
      if (l.upsampled) radiance += upsampledPhotonMap(v, l, x, y);
    writeDenoised(v, pixel, radiance);
  }
}

// The last pass of an odd pixel under quarter photon passes whose direct signal's passes ended
// earlier: nothing left to filter, its photon-map signal interpolated.
PVR_HOST_DEVICE inline void finishOddPixel(const DenoiseFrameView& v, const AtrousLevels& l, int x, int y) {
  const size_t pixel = denoisePixel(v.camera, x, y);
  Vec3 radiance = upsampledPhotonMap(v, l, x, y);
  if (l.finished) radiance += l.finished[pixel].colour;
  writeDenoised(v, pixel, radiance);
}

// Step 5 without a-trous passes (iterations 0), at a pixel the eye filters: level 0 remodulated,
// and kept as the history.
template <int S>
PVR_HOST_DEVICE inline void remodulateAccumulatedOf(const DenoiseFrameView& v, int x, int y) {
  const size_t pixel = denoisePixel(v.camera, x, y);
  Vec3 radiance{0, 0, 0};
  for (int s = 0; s < S; ++s) {
    const ColourVariance c = v.levels[s][0][pixel];
    v.historyOut[s][pixel] = c;
    radiance += c.colour;
  }
  writeDenoised(v, pixel, radiance);
}

PVR_HOST_DEVICE inline bool accumulateDenoisePixel(const DenoiseFrameView& v, int x, int y) {
  return v.twoSignals() == 2 ? accumulateDenoisePixelOf<2>(v, x, y) : accumulateDenoisePixelOf<1>(v, x, y);
}
PVR_HOST_DEVICE inline void estimateDenoiseVariance(const DenoiseFrameView& v, int x, int y) {
  if (v.twoSignals() == 2) estimateDenoiseVarianceOf<2>(v, x, y);
  else estimateDenoiseVarianceOf<1>(v, x, y);
}
PVR_HOST_DEVICE inline void atrousDenoisePixel(const DenoiseFrameView& v, int iteration, const AtrousLevels& l, int x,
                                               int y) {
  const MemoryTaps taps{v, l};
  if (l.signals == 2) atrousDenoisePixelOf<2>(v, iteration, l, taps, x, y);
  else atrousDenoisePixelOf<1>(v, iteration, l, taps, x, y);
}
// A pass after the first under quarter photon passes, at a pixel of the half it runs over
// (atrousLevels(v, iteration, Even or Odd)).
PVR_HOST_DEVICE inline void atrousDenoisePixelQuarter(const DenoiseFrameView& v, int iteration, const AtrousLevels& l,
                                                      int x, int y) {
  const QuarterMemoryTaps taps{v, l};
  if (l.signals == 2) atrousDenoisePixelOf<2>(v, iteration, l, taps, x, y);
  else if (l.signals == 1) atrousDenoisePixelOf<1>(v, iteration, l, taps, x, y);
  else if (l.upsampled) finishOddPixel(v, l, x, y);
}
PVR_HOST_DEVICE inline void remodulateAccumulated(const DenoiseFrameView& v, int x, int y) {
  if (v.twoSignals() == 2) remodulateAccumulatedOf<2>(v, x, y);
  else remodulateAccumulatedOf<1>(v, x, y);
}

}  // namespace pvr
