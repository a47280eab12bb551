#pragma once
// TAA on the host (the CPU backend's): one eye's history and the resolve over its pixels.
#include <vector>

#include "pvr/image/image.h"
#include "pvr/temporal/taa.h"

namespace pvr {

// One eye's last resolved image (the displayed one without its emitted part), with the depth and
// camera it was rendered with.
struct TaaHistory {
  Image image;
  std::vector<float> inverseDepth;
  EyeCamera camera;
  bool valid = false;
};

// Blends `current` (with its per-pixel inverse depth, and sample spacing if foveated, else null)
// with `history` reprojected to `camera` into `displayed`, which (less the emitted part, if given)
// becomes the new history. Returns the number of pixels that took history. A history of another
// eye size is dropped.
size_t resolveTemporal(const EyeCamera& camera, const TaaParams& params, const Image& current,
                       const std::vector<float>& inverseDepth, const float* sampleSpacing, TaaHistory& history,
                       Image& displayed, const TaaEmitted& emission = TaaEmitted());

}  // namespace pvr
