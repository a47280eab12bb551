#pragma once
// The denoise stage's options (the passes are in svgf.h): what a frame's options carry.

namespace pvr {

struct DenoiseParams {
  int iterations = 5;            ///< a-trous passes (0: temporal accumulation only)
  int directIterations = 5;      ///< of them, the passes of the direct (shadow-ray) signal (1..iterations; svgf.h)
  float colourAlpha = 0.2f;      ///< the current frame's least weight in the accumulated colour
  float momentsAlpha = 0.2f;     ///< the same for the luminance moments
  float sigmaLuminance = 4.0f;   ///< luminance edge-stopping, in local standard deviations
  float normalPower = 128.0f;    ///< normal edge-stopping: exp(-power (1 - cos))
  float depthTolerance = 0.02f;  ///< relative inverse-depth difference off the pixel's plane: another surface
  // A moving head's history read by Catmull-Rom where its taps agree (else bilinear). Off by
  // default: on the H100 it cost 0.22 ms a stereo frame on Sponza for 3 % less error, and
  // nothing on Cornell (docs/benchmarks.md, "The denoiser's history read").
  bool bicubicHistory = false;
  // The photon-map signal's a-trous passes after the first on the even pixels alone (x and y even:
  // a quarter of them), whose taps at steps 2, 4, ... land on even pixels only, so the values there
  // are the full filter's to the bit; the other pixels interpolate the last pass's output from
  // their even neighbours on the same surface (docs/denoising.md). Off: on the H100 it was slower
  // than the full filter (strided reads of the even pixels), the CPU's passes take half the time.
  bool quarterPhotonPasses = false;
  // Progressive refinement while the head is still (within the tolerances below from the last
  // frame): the frames' signals are averaged with 1 / n (not the moving head's alpha floor), new
  // photons each frame with a radius shrinking by Knaus-Zwicker's rule (refineAlpha, down to
  // minRadiusFraction of the first), and the filter fades out as the average's own variance
  // falls, so the picture converges to the unbiased image. Any movement returns to the moving
  // head's weights: the average's frame count halves each frame down to theirs, no pop.
  bool refineWhenStill = true;
  float stillPosition = 1e-3f;      ///< head movement (scene units) that still counts as still
  float stillAngleDegrees = 0.05f;  ///< head rotation that still counts as still
  float refineAlpha = 0.7f;
  float minRadiusFraction = 0.25f;
};

// The denoise stage's options.
struct DenoiseOptions {
  bool enabled = false;
  DenoiseParams params;
};

constexpr int kMaxDenoiseIterations = 8;

}  // namespace pvr
