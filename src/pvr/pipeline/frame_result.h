#pragma once
// What a frame gives back: each eye's images, the time of each stage, and counts. An eye's
// per-pixel outputs are there only when a stage of this frame wrote them (std::nullopt
// otherwise): first hits only at full resolution, sample spacing only when foveated, the
// reuse map only for the right eye under stereo reuse.
#include <cstdint>
#include <optional>
#include <vector>

#include "pvr/image/image.h"

namespace pvr {

struct StageTimings {
  double photonTraceMs = 0, mapBuildMs = 0, eyeMs[2] = {0, 0};
  // --primary raster: the G-buffer pre-pass of both eyes (GPU time of the Vulkan pass, or the
  // host's wait for it on the CPU backend).
  double primaryMs = 0;
  double primaryDrawMs = 0;  ///< of primaryMs, the raster passes (the rest: copying their targets into the shared buffer)
  // Within an eye: eye rays (to the gather points) and density estimation; for the single
  // kernel everything is eye rays.
  double eyeRayMs[2] = {0, 0}, densityMs[2] = {0, 0};
  // Scatter's projection of the left hit points into the right image (visibility rays and
  // atomics), counted in the right eye's time.
  double scatterMs = 0;
  // Foveated: the reconstruction of each eye's image from its mask vertices (in eyeMs).
  double reconstructMs[2] = {0, 0};
  // Denoising each eye's image (in eyeMs).
  double denoiseMs[2] = {0, 0};
  // TAA: resolving each eye's image against its history (in eyeMs).
  double temporalMs[2] = {0, 0};
  double totalMs() const { return photonTraceMs + mapBuildMs + primaryMs + eyeMs[0] + eyeMs[1]; }
};

struct EyeResult {
  Image image;  ///< what the eye is shown: denoised and after TAA when they are on
  /// Per pixel, 1 / view depth of what it shows (0: nothing hit); foveated: blended from the
  /// vertices' like the colour.
  std::vector<float> inverseDepth;
  /// Full resolution: per pixel, the triangle its centre ray hit first (~0u: none). Foveated
  /// pixels are blends of several rays and have none.
  std::optional<std::vector<uint32_t>> firstPrim;
  /// Foveated: per pixel, the spacing in pixels of the samples it was rebuilt from.
  std::optional<std::vector<float>> sampleSpacing;
  /// The right eye under stereo reuse at full resolution: per pixel, the left pixel whose
  /// shading it took (kNotReused: shaded here). Foveated reuse is per vertex and has none.
  std::optional<std::vector<uint32_t>> reusedFrom;
};

struct FrameResult {
  EyeResult eyes[2];  ///< empty when the eye was not rendered or the caller asked for timings only
  StageTimings timings;
  size_t storedPhotons = 0;
  size_t mapBytes = 0;
  size_t deviceBytes = 0;  ///< GPU memory held by the backend (0 on the CPU)
  size_t cacheCells = 0;     ///< DensityScheme::SurfaceCache: cells estimated this frame (both eyes)
  size_t cacheUnplaced = 0;  ///< and points whose cell found no slot (estimated on their own)
  size_t reusedPixels = 0;  ///< right-eye pixels (mask vertices when foveated) that took the left eye's shading
  size_t shadedSamples[2] = {0, 0};  ///< per eye: pixels, or mask vertices when foveated
  size_t historyPixels[2] = {0, 0};  ///< TAA: per eye, pixels that blended in their history
  float gaze[2][2] = {{0.5f, 0.5f}, {0.5f, 0.5f}};  ///< foveated: the gaze each eye was rendered with
};

}  // namespace pvr
