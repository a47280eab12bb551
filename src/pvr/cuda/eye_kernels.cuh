#pragma once
// Device helpers shared by the eye-pass kernels (full resolution, foveated, density, scatter, and
// the ray-throughput benchmark): 8x8 pixel tiles, per-pixel outputs, the stereo role's paths.
#include "pvr/cuda/eye_pass.cuh"
#include "pvr/cuda/traversal_stack.cuh"

namespace pvr::cuda {

constexpr int kTile = 8;  // 8x8-pixel blocks: each warp an 8x4 tile of coherent rays and hit points

__device__ inline bool tilePixel(int width, int height, int& x, int& y) {
  x = int(blockIdx.x) * kTile + int(threadIdx.x);
  y = int(blockIdx.y) * kTile + int(threadIdx.y);
  return x < width && y < height;
}

inline dim3 tileGrid(int width, int height) { return dim3(unsigned((width + kTile - 1) / kTile), unsigned((height + kTile - 1) / kTile)); }

// Waits until every lane of the warp has finished shading, before a list kernel's stores; every
// lane must call it (none may return before). ptxas 13.0 (sm_90) gave vertexRaysKernel's stores
// the uniform registers that held the local frame's address, while lanes of the same warp that
// lagged were still shading through it: their clipAtBoundaries read `params` out of bounds
// (illegal address, foveated Sponza; docs/reliability.md).
__device__ inline void finishShadingTogether() { __syncwarp(); }

// Stores the sample's contribution: the running sum, scaled on the last sample (the CPU's order).
__device__ inline void storeSample(Vec3* image, size_t pixel, Vec3 c, int sample, int samples) {
  Vec3 v = sample == 0 ? c : image[pixel] + c;
  if (sample == samples - 1 && samples > 1) v *= 1.0f / float(samples);
  image[pixel] = v;
}

// Everything of a pixel but its radiance and surface: first-hit id and the reuse decision (counted
// per warp: one atomic per warp, not per pixel).
__device__ inline void recordPixel(const EyeOutputs& out, size_t pixel, const PixelSample& p) {
  out.firstPrim[pixel] = p.firstPrim;
  out.inverseDepth[pixel] = p.inverseDepth;
  if (!out.reusedFrom) return;
  out.reusedFrom[pixel] = p.reusedFrom;
  countInWarp(out.reusedCount, p.reusedFrom != kNotReused);
}

// The denoiser's guides of one sample's gather point: the emitted and direct parts summed like
// the image, albedo and normal from sample 0.
__device__ inline void recordGuide(const EyeOutputs& out, size_t pixel, const GatherPoint& p, int sample, int samples) {
  if (!out.direct) return;
  storeSample(out.emitted, pixel, p.emitted, sample, samples);
  storeSample(out.direct, pixel, p.radiance, sample, samples);
  if (sample > 0) return;
  out.albedo[pixel] = p.reflectance;
  out.normal[pixel] = p.normal;
}

// An eye's part in stereo reuse (pvr::StereoRole) is a compile-time kernel parameter: the reuse
// code paths cost registers, so an eye that does not reuse gets kernels without them.
template <StereoRole R>
__device__ inline StereoReuseView reuseFor(const StereoReuseView& reuse) {
  if constexpr (R == StereoRole::Reuser) return reuse;
  else return StereoReuseView();
}

template <StereoRole R>
__device__ inline SurfaceRecord* surfaceFor(const EyeOutputs& out, size_t pixel) {
  if constexpr (R == StereoRole::Source) return out.surfaces + pixel;
  else return nullptr;
}

}  // namespace pvr::cuda
