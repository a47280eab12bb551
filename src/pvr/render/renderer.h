#pragma once
// One stereo frame: trace photons, build the photon map, shade the requested eyes, with the
// time of every stage. Backend-neutral options; the CPU backend is the reference.
#include <string>
#include <vector>

#include "pvr/cpu/cpu_backend.h"
#include "pvr/render/image.h"

namespace pvr {

enum class PhotonMapKind : int { HashGrid = 0, KdTree = 1 };

struct RenderOptions {
  uint32_t photonsX = 256, photonsY = 256;  ///< emitted photons = photonsX * photonsY (the paper's NxN)
  int maxPhotonDepth = 8;
  PhotonMapKind map = PhotonMapKind::HashGrid;
  GatherParams gather;  ///< radius, estimator, k, shading mode, spp, seed
  bool eyes[2] = {true, true};
  uint32_t photonCount() const { return photonsX * photonsY; }
};

struct StageTimings {
  double photonTraceMs = 0, mapBuildMs = 0, eyeMs[2] = {0, 0};
  double totalMs() const { return photonTraceMs + mapBuildMs + eyeMs[0] + eyeMs[1]; }
};

struct EyeResult {
  Image image;
  std::vector<uint32_t> firstPrim;  ///< per pixel, the triangle its centre ray hit first (~0u: none)
};

struct FrameResult {
  EyeResult eyes[2];
  StageTimings timings;
  size_t storedPhotons = 0;
  size_t mapBytes = 0;
};

// Checks options against the scene and the rig; throws pvr::Error naming the bad value.
void validateOptions(const RenderOptions& options, const StereoRig& rig);

FrameResult renderFrame(const CpuBackend& backend, const StereoRig& rig, const RenderOptions& options);

}  // namespace pvr
