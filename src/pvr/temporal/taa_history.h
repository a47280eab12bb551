#pragma once
// TAA on the host (the CPU backend's): one eye's history and the resolve over its pixels.
#include <vector>

#include "pvr/frame/frame.h"
#include "pvr/temporal/taa.h"

namespace pvr {

// One eye's last displayed image, with the depth and camera it was rendered with.
struct TaaHistory {
  Image image;
  std::vector<float> inverseDepth;
  EyeCamera camera;
  bool valid = false;
};

// Blends `eye`'s image (which needs its inverseDepth; sampleSpacing if foveated) with `history`
// reprojected to `camera`, replaces eye.image with the result and makes it the new history.
// Returns the number of pixels that took history. A history of another eye size is dropped.
size_t resolveTemporal(const EyeCamera& camera, const TaaParams& params, EyeResult& eye, TaaHistory& history);

}  // namespace pvr
