#pragma once
// What a frame renders: each stage's options gathered in one struct, and the one place where
// they are checked (validateOptions), in the library's own words.
#include <string>

#include "pvr/camera/stereo_rig.h"
#include "pvr/denoise/denoise_options.h"
#include "pvr/foveation/foveation_options.h"
#include "pvr/photon/gather.h"
#include "pvr/photon/photon_map.h"
#include "pvr/photon/photon_trace.h"
#include "pvr/photon/surface_cache.h"
#include "pvr/stereo/stereo_reuse.h"
#include "pvr/temporal/taa.h"
#include "pvr/util/error.h"

namespace pvr {

// How the GPU splits eye rays and density estimation (the main paper's section 3.2). Every scheme
// computes the same image; the CPU backend computes it one way.
enum class DensityKernel : int {
  Single = 0,        ///< one kernel traces the eye ray and estimates (the paper's "OptiX-only")
  Hybrid = 1,        ///< the eye-ray kernel writes gather points, a second kernel estimates
  SharedMemory = 2,  ///< hybrid, estimation by the paper's Algorithm 1 (8x8 blocks stage photons)
  CellSorted = 3,    ///< hybrid, gather points sorted by hash cell first, so each warp estimates one cell
};

const char* densityKernelName(DensityKernel k);  ///< "single" | "hybrid" | "shared" | "sorted"

// Where the photon-map estimates come from.
enum class DensityScheme : int {
  PerPixel = 0,      ///< the main paper's: an estimate at every gather point (by the kernel above)
  SurfaceCache = 1,  ///< one per surface cell, shared by the pixels and eyes near it (photon/surface_cache.h)
};
const char* densitySchemeName(DensityScheme s);  ///< "pixel" | "cache"

// Where the eye pass's first hits come from (sample 0, through the pixel centres).
enum class PrimaryVisibility : int {
  Rays = 0,    ///< traced
  Raster = 1,  ///< Ray-VR's G-buffer pre-pass: both eyes rasterised by Vulkan (raster/gbuffer_raster.h)
};
const char* primaryVisibilityName(PrimaryVisibility p);  ///< "rays" | "raster"

// Where the GPU's full-resolution eye passes trace their rays (hybrid, shared-memory, cell-sorted
// and cache schemes with traced first hits; the paper's single kernel and foveated passes keep
// them in one kernel). The image is the same each way but for rounding (the compiler contracts
// the shading arithmetic differently in each kernel); the CPU always traces in place.
enum class RaySchedule : int {
  Auto = 0,      ///< per eye pass by its shadow queries per gather point (eyeRayScheduleFor)
  InKernel = 1,  ///< camera, shadow and specular rays all in the eye kernel (the paper's hybrid)
  FirstHits = 2, ///< sample 0's camera rays in a kernel of their own (PrimaryHitsView::traced)
  Deferred = 3,  ///< FirstHits, and the shadow rays in a kernel of their own (photon/deferred_shadows.h)
};
const char* rayScheduleName(RaySchedule s);  ///< "auto" | "in-kernel" | "first-hits" | "deferred"

// Auto's choice for an eye pass whose gather points ask `shadowQueries` shadow rays each: kernels
// of their own pay where a point asks several (the eye kernel's registers then hold up more rays:
// measured 2026-12-05 on the H100, docs/benchmarks.md), not where it asks one (cornell-dense's
// area light). A right eye that reuses the left's shading shades few pixels: no deferral there;
// with first hits apart it shades over a list of the pixels it does not reuse (0.6-1.2 ms a
// stereo frame faster on the cathedrals than in-kernel). That listed pass's non-finite pixels
// (2026-12-06/07) stopped with a30ef05's workaround for the compiler fault found in the foveated
// pass (finishShadingTogether; docs/reliability.md).
inline RaySchedule eyeRayScheduleFor(int shadowQueries, bool reuser) {
  if (shadowQueries >= 3 && !reuser) return RaySchedule::Deferred;
  if (shadowQueries >= 2) return RaySchedule::FirstHits;
  return RaySchedule::InKernel;
}

struct RenderOptions {
  uint32_t photonsX = 256, photonsY = 256;  ///< emitted photons = photonsX * photonsY (the paper's NxN)
  int maxPhotonDepth = 8;
  // A rolling photon map: the N photons in this many slices, one retraced per frame (with new
  // random numbers under TAA or the denoiser), so consecutive frames share all but one slice:
  // 1/N of the photon tracing a frame (measured: no less flicker, more error; docs/denoising.md).
  // 1: every photon every frame. A
  // still head's refinement, and any change of the photons' options, retrace them all.
  int photonBatches = 1;
  PhotonMapKind map = PhotonMapKind::HashGrid;
  DensityKernel kernel = DensityKernel::Hybrid;
  DensityScheme density = DensityScheme::PerPixel;
  float cacheCellFraction = kDefaultCacheCellFraction;  ///< the surface cache's cell side over the radius
  PrimaryVisibility primary = PrimaryVisibility::Rays;
  RaySchedule raySchedule = RaySchedule::Auto;
  GatherParams gather;  ///< radius, estimator, k, shading mode, spp, seed
  bool eyes[2] = {true, true};
  StereoMode stereo = StereoMode::Separate;  ///< how the right eye reuses the left eye's shading
  FoveationOptions foveation;
  DenoiseOptions denoise;  ///< before TAA, which then resolves the denoised image
  TemporalOptions temporal;
  uint32_t photonCount() const { return photonsX * photonsY; }
  // The photon pass these options ask for (every backend traces the same photons).
  PhotonTraceParams photonTraceParams() const {
    PhotonTraceParams p;
    p.photonCount = photonCount();
    p.seed = gather.sequenceIndex ? hashCombine(gather.seed, 0x7e3a9u + gather.sequenceIndex) : gather.seed;  // new each frame of a run
    p.maxDepth = maxPhotonDepth;
    p.storeDirect = gather.mode == ShadingMode::PhotonMapOnly;  // the map alone then shades
    return p;
  }
};

constexpr int kMaxEyeDimension = 8192;
constexpr uint64_t kMaxPhotons = uint64_t(1) << 26;  ///< 8192x8192
constexpr int kMaxSamplesPerPixel = 4096;
constexpr int kMaxPathDepth = 64;
constexpr int kMaxShadowRays = 64;

// The option an OptionError is about, so that a front end can name it its own way (the command
// line names its flag).
enum class RenderOption : int {
  Photons, PhotonDepth, Radius, K, SamplesPerPixel, SpecularDepth, ShadowRays, EyeSize, Ipd, Kernel, Gaze, TaaBlend,
  TaaDepthTolerance, Stereo, DenoiseIterations, DenoiseDirectIterations, DenoiseParameter, PhotonBatches, Density, CacheCell,
};

constexpr int kMaxPhotonBatches = 64;

class OptionError : public Error {
 public:
  OptionError(RenderOption option, const std::string& message) : Error(message), option_(option) {}
  RenderOption option() const { return option_; }

 private:
  RenderOption option_;
};

// Checks the rig a frame is rendered for (eye size, IPD); throws OptionError.
void validateRig(const StereoRig& rig);
// Checks options against the rig (and the rig); throws OptionError naming the bad value.
void validateOptions(const RenderOptions& options, const StereoRig& rig);

}  // namespace pvr
