#pragma once
// A converged reference of a view: progressive photon mapping in Knaus and Zwicker's (2011)
// probabilistic form. Pass i is an independent frame of the same pipeline (same scene, materials,
// camera and backend) with its own random numbers and radius r_i, where
//   r_{i+1}^2 = r_i^2 (i + alpha) / (i + 1),
// and the reference is the average of the passes. The variance of the average falls as
// O(n^-alpha) and the radius' bias as O(n^(alpha-1)), so the average converges to the unbiased
// image; direct light (shadow rays) and the sub-pixel positions average over the passes as
// ordinary Monte Carlo.
#include <cstdint>
#include <vector>

#include "pvr/image/image.h"
#include "pvr/pipeline/frame_renderer.h"

namespace pvr {

struct ReferenceSettings {
  float alpha = 0.7f;  ///< Knaus-Zwicker's alpha in (0, 1): the share of photons' radius kept per pass
  // Every sample jittered over its pixel (the pixel's box-filtered integral); false: the first
  // sample of each pass through the pixel centre, as the real-time image's.
  bool boxFilter = true;
};

constexpr int kMaxReferencePasses = 1 << 20;

class ProgressiveReference {
 public:
  // Renders with `renderer` the view of `rig` under `options` (its photon count, first radius,
  // samples per pixel and seed per pass; stereo reuse, foveation and TAA are turned off: each
  // eye is rendered on its own at full resolution). Throws OptionError for options out of range.
  ProgressiveReference(FrameRenderer& renderer, const StereoRig& rig, const RenderOptions& options,
                       const ReferenceSettings& settings = {});

  void addPass();  ///< one more frame into the average
  int passes() const { return passes_; }
  float radiusOfPass(int pass) const;  ///< r_pass (pass counted from 0)
  double frameMs() const { return frameMs_; }  ///< the pipeline's time of the passes so far

  Image image(Eye eye) const;  ///< the average of the passes (empty for an eye not rendered)
  // The variance part of the average's error, as the relative MSE compareToReference reports:
  // mean over pixels and channels of (s^2 / n) / (mean^2 + 0.01), s^2 the passes' sample
  // variance, over the pixels whose `mask` entry is non-zero (all if empty). The radius' bias is
  // not in it. Infinity before two passes.
  double estimatedRelMse(Eye eye, const std::vector<uint8_t>& mask = {}) const;

 private:
  FrameRenderer& renderer_;
  StereoRig rig_;
  RenderOptions options_;
  ReferenceSettings settings_;
  int passes_ = 0;
  double frameMs_ = 0;
  std::vector<double> sum_[2], sumSquares_[2];  ///< per pixel and channel
};

}  // namespace pvr
