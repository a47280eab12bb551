#pragma once
// One stereo frame, whatever the backend: its options (photons, photon map, density estimation,
// GPU kernel scheme), the time of each stage, and the images. The CPU backend (Embree + TBB) is
// the reference; the CUDA backend must agree with it.
#include <algorithm>
#include <string>
#include <vector>

#include "pvr/camera/stereo_rig.h"
#include "pvr/frame/image.h"
#include "pvr/photon/gather.h"
#include "pvr/photon/photon_trace.h"
#include "pvr/temporal/taa.h"

namespace pvr {

struct FoveationMask;  // pvr/foveation/mask.h

// Foveated rendering: rays only through the mask's vertices around each eye's gaze, the image
// reconstructed from them (the foveated ray tracing document).
struct FoveationOptions {
  const FoveationMask* mask = nullptr;  ///< null: every pixel is shaded
  float gaze[2][2] = {{0.5f, 0.5f}, {0.5f, 0.5f}};  ///< per eye, gaze point in [0, 1]^2 of the image (x right, y down)
  /// One gaze for both eyes, as eyes look: gaze[0] is the left eye's, and the right eye fixates
  /// the surface point the left eye's gaze ray meets (vergence); gaze[1] is then ignored.
  bool verge = false;
  // The gaze's pixel for an eye of width x height.
  void gazePixel(int eye, int width, int height, int& x, int& y) const {
    x = std::min(width - 1, std::max(0, int(gaze[eye][0] * float(width))));
    y = std::min(height - 1, std::max(0, int(gaze[eye][1] * float(height))));
  }
  size_t gazePixelIndex(int eye, int width, int height) const {
    int x, y;
    gazePixel(eye, width, height, x, y);
    return size_t(y) * size_t(width) + size_t(x);
  }
};

// Temporal anti-aliasing across the frames a renderer draws (pvr/temporal/taa.h): each eye's
// displayed image blends in the previous one, reprojected by depth and the head's motion.
struct TemporalOptions {
  bool enabled = false;
  TaaParams taa;
};

enum class PhotonMapKind : int { HashGrid = 0, KdTree = 1 };

// How the GPU splits eye rays and density estimation (the main paper's section 3.2). Every scheme
// computes the same image; the CPU backend computes it one way.
enum class DensityKernel : int {
  Single = 0,        ///< one kernel traces the eye ray and estimates (the paper's "OptiX-only")
  Hybrid = 1,        ///< the eye-ray kernel writes gather points, a second kernel estimates
  SharedMemory = 2,  ///< hybrid, estimation by the paper's Algorithm 1 (8x8 blocks stage photons)
  CellSorted = 3,    ///< hybrid, gather points sorted by hash cell first, so each warp estimates one cell
};

const char* densityKernelName(DensityKernel k);
const char* stereoModeName(StereoMode m);  ///< "separate" | "scatter" | "gather"
// "separate" | "scatter" | "gather"; throws pvr::Error naming `what` otherwise.
StereoMode parseStereoMode(const std::string& text, const std::string& what = "--stereo");

struct RenderOptions {
  uint32_t photonsX = 256, photonsY = 256;  ///< emitted photons = photonsX * photonsY (the paper's NxN)
  int maxPhotonDepth = 8;
  PhotonMapKind map = PhotonMapKind::HashGrid;
  DensityKernel kernel = DensityKernel::Hybrid;
  GatherParams gather;  ///< radius, estimator, k, shading mode, spp, seed
  bool eyes[2] = {true, true};
  StereoMode stereo = StereoMode::Separate;  ///< how the right eye reuses the left eye's shading
  FoveationOptions foveation;
  TemporalOptions temporal;
  uint32_t photonCount() const { return photonsX * photonsY; }
  // The photon pass these options ask for (every backend traces the same photons).
  PhotonTraceParams photonTraceParams() const {
    PhotonTraceParams p;
    p.photonCount = photonCount();
    p.seed = gather.seed;
    p.maxDepth = maxPhotonDepth;
    p.storeDirect = gather.mode == ShadingMode::PhotonMapOnly;  // the map alone then shades
    return p;
  }
};

struct StageTimings {
  double photonTraceMs = 0, mapBuildMs = 0, eyeMs[2] = {0, 0};
  // Within an eye: eye rays (to the gather points) and density estimation; for the single
  // kernel everything is eye rays.
  double eyeRayMs[2] = {0, 0}, densityMs[2] = {0, 0};
  // Scatter's projection of the left hit points into the right image (visibility rays and
  // atomics), counted in the right eye's time.
  double scatterMs = 0;
  // Foveated: the reconstruction of each eye's image from its mask vertices (in eyeMs).
  double reconstructMs[2] = {0, 0};
  // TAA: resolving each eye's image against its history (in eyeMs).
  double temporalMs[2] = {0, 0};
  double totalMs() const { return photonTraceMs + mapBuildMs + eyeMs[0] + eyeMs[1]; }
};

struct EyeResult {
  Image image;  ///< what the eye is shown: after TAA when it is on
  /// Per pixel, the triangle its centre ray hit first (~0u: none); empty for foveated frames,
  /// whose pixels are blends of several rays.
  std::vector<uint32_t> firstPrim;
  /// Per pixel, 1 / view depth of what it shows (0: nothing hit); foveated: blended from the
  /// vertices' like the colour.
  std::vector<float> inverseDepth;
  /// Foveated: per pixel, the spacing in pixels of the samples it was rebuilt from. Empty: 1.
  std::vector<float> sampleSpacing;
  /// The right eye under stereo reuse: per pixel, the left pixel whose shading it took
  /// (kNotReused: shaded here). Empty otherwise, and for foveated frames (reuse is per vertex).
  std::vector<uint32_t> reusedFrom;
};

struct FrameResult {
  EyeResult eyes[2];  ///< empty images when the caller asked for timings only
  StageTimings timings;
  size_t storedPhotons = 0;
  size_t mapBytes = 0;
  size_t deviceBytes = 0;  ///< GPU memory held by the backend (0 on the CPU)
  size_t reusedPixels = 0;  ///< right-eye pixels (mask vertices when foveated) that took the left eye's shading
  size_t shadedSamples[2] = {0, 0};  ///< per eye: pixels, or mask vertices when foveated
  size_t historyPixels[2] = {0, 0};  ///< TAA: per eye, pixels that blended in their history
  float gaze[2][2] = {{0.5f, 0.5f}, {0.5f, 0.5f}};  ///< foveated: the gaze each eye was rendered with
};

// Vergence: sets foveation.gaze[1] (image fractions, clamped to the image) to where the right eye
// sees the point at inverse depth *leftInverseDepthAtGaze (0: at infinity) on the ray through the
// centre of the left eye's gaze pixel; to the left eye's image position if that is null (the
// left eye not rendered) or the point is behind the right eye.
void vergeRightGaze(const StereoRig& rig, FoveationOptions& foveation, const float* leftInverseDepthAtGaze);

// Sets the rig's per-eye resolution from "WxH" (1x1 .. 8192x8192); throws pvr::Error naming
// --eye-size otherwise.
void setEyeSize(StereoRig& rig, const std::string& text);

// Checks options against the rig; throws pvr::Error naming the bad value.
void validateOptions(const RenderOptions& options, const StereoRig& rig);

class FrameRenderer {
 public:
  virtual ~FrameRenderer() = default;
  // Traces photons, builds the map and shades the requested eyes. With images = false the
  // images stay where they were rendered (benchmarks).
  // With options.temporal on, each eye's image is blended with the renderer's history of the
  // frames before (kept per eye; an eye whose size changed starts again).
  virtual FrameResult render(const StereoRig& rig, const RenderOptions& options, bool images = true) = 0;
  // Forgets the TAA history (a cut: the next frame is shown as rendered).
  virtual void resetHistory() = 0;
  virtual std::string name() const = 0;  ///< "cpu" or "cuda"
  virtual std::string deviceName() const = 0;
};

}  // namespace pvr
