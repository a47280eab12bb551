#include "pvr/pipeline/frame_options.h"

#include <cmath>

#include "pvr/foveation/mask.h"

namespace pvr {

const char* densityKernelName(DensityKernel k) {
  switch (k) {
    case DensityKernel::Single: return "single";
    case DensityKernel::Hybrid: return "hybrid";
    case DensityKernel::SharedMemory: return "shared";
    case DensityKernel::CellSorted: return "sorted";
  }
  return "?";
}

const char* densitySchemeName(DensityScheme s) { return s == DensityScheme::SurfaceCache ? "cache" : "pixel"; }
const char* primaryVisibilityName(PrimaryVisibility p) { return p == PrimaryVisibility::Raster ? "raster" : "rays"; }
const char* rayScheduleName(RaySchedule s) {
  switch (s) {
    case RaySchedule::InKernel: return "in-kernel";
    case RaySchedule::FirstHits: return "first-hits";
    case RaySchedule::Deferred: return "deferred";
    default: return "auto";
  }
}

void validateRig(const StereoRig& rig) {
  if (rig.width < 1 || rig.height < 1 || rig.width > kMaxEyeDimension || rig.height > kMaxEyeDimension)
    throw OptionError(RenderOption::EyeSize, "the eye size must be between 1x1 and " + std::to_string(kMaxEyeDimension) +
                                                 "x" + std::to_string(kMaxEyeDimension) + ", got " +
                                                 std::to_string(rig.width) + "x" + std::to_string(rig.height));
  if (!(rig.ipd >= 0.0f) || !std::isfinite(rig.ipd))
    throw OptionError(RenderOption::Ipd, "the IPD must be a non-negative finite number, got " + std::to_string(rig.ipd));
}

void validateOptions(const RenderOptions& o, const StereoRig& rig) {
  validateRig(rig);
  if (o.photonsX == 0 || o.photonsY == 0) throw OptionError(RenderOption::Photons, "the number of photons must be positive");
  if (uint64_t(o.photonsX) * o.photonsY > kMaxPhotons)
    throw OptionError(RenderOption::Photons, "too many photons: " + std::to_string(uint64_t(o.photonsX) * o.photonsY) +
                                                 " (at most " + std::to_string(kMaxPhotons) + ", 8192x8192)");
  if (o.photonBatches < 1 || o.photonBatches > kMaxPhotonBatches || uint64_t(o.photonBatches) > uint64_t(o.photonsX) * o.photonsY)
    throw OptionError(RenderOption::PhotonBatches, "the photon batches must be between 1 and " +
                                                       std::to_string(kMaxPhotonBatches) + ", and at most the photons");
  if (o.maxPhotonDepth < 1 || o.maxPhotonDepth > kMaxPathDepth)
    throw OptionError(RenderOption::PhotonDepth, "the photon depth must be between 1 and " + std::to_string(kMaxPathDepth));
  const DensityParams& d = o.gather.density;
  if (!(d.radius > 0.0f) || !std::isfinite(d.radius))
    throw OptionError(RenderOption::Radius, "the search radius must be a positive finite number");
  if (d.estimator == Estimator::Knn && (d.k < 1 || d.k > kMaxKnn))
    throw OptionError(RenderOption::K, "k must be between 1 and " + std::to_string(kMaxKnn));
  if (o.gather.samplesPerPixel < 1 || o.gather.samplesPerPixel > kMaxSamplesPerPixel)
    throw OptionError(RenderOption::SamplesPerPixel,
                      "samples per pixel must be between 1 and " + std::to_string(kMaxSamplesPerPixel));
  if (o.gather.pathDepth < 1 || o.gather.pathDepth > kMaxPathDepth)
    throw OptionError(RenderOption::SpecularDepth, "the path level's depth must be between 1 and " + std::to_string(kMaxPathDepth));
  if (o.gather.overrideEffects && int(o.gather.effects) >= kEffectLevels)
    throw OptionError(RenderOption::SpecularDepth, "unknown effect level " + std::to_string(int(o.gather.effects)));
  if (o.gather.maxSpecularDepth < 0 || o.gather.maxSpecularDepth > kMaxPathDepth)
    throw OptionError(RenderOption::SpecularDepth, "the specular depth must be between 0 and " + std::to_string(kMaxPathDepth));
  if (o.gather.punctualShadowRays < 0 || o.gather.punctualShadowRays > kMaxShadowRays)
    throw OptionError(RenderOption::ShadowRays,
                      "the shadow rays per point must be between 0 (one per light) and " + std::to_string(kMaxShadowRays));
  if ((o.kernel == DensityKernel::SharedMemory || o.kernel == DensityKernel::CellSorted) &&
      o.map != PhotonMapKind::HashGrid)
    throw OptionError(RenderOption::Kernel,
                      std::string("the ") + densityKernelName(o.kernel) + " kernel works on the hash grid, not the kd-tree");
  if (o.density == DensityScheme::SurfaceCache) {
    if (!(o.cacheCellFraction >= kMinCacheCellFraction && o.cacheCellFraction <= kMaxCacheCellFraction))
      throw OptionError(RenderOption::CacheCell, "the surface cache's cell must be between " +
                                                     std::to_string(kMinCacheCellFraction).substr(0, 4) + " and " +
                                                     std::to_string(kMaxCacheCellFraction).substr(0, 3) + " of the radius");
    if (o.foveation.mask)
      throw OptionError(RenderOption::Density, "the surface cache shades full-resolution eyes: a foveated pass "
                                               "estimates at its mask's vertices (use --density pixel)");
    if (d.boundary == Boundary::Clipped)
      throw OptionError(RenderOption::Density, "the surface cache's cells mix points on both sides of a wall: "
                                               "--boundary clipped estimates per pixel (use --density pixel)");
  }
  for (int e = 0; e < 2; ++e)
    for (float g : o.foveation.gaze[e])
      if (!(g >= 0.0f && g <= 1.0f))
        throw OptionError(RenderOption::Gaze, "the gaze must lie in the image: coordinates between 0 and 1");
  if (o.foveation.mask) checkMaskFits(*o.foveation.mask, rig.width, rig.height);
  if (o.temporal.enabled) {
    const TaaParams& t = o.temporal.taa;
    if (!(t.blend > 0.0f && t.blend <= 1.0f)) throw OptionError(RenderOption::TaaBlend, "the TAA blend must be in (0, 1]");
    if (!(t.depthTolerance > 0.0f && t.depthTolerance < 1.0f))
      throw OptionError(RenderOption::TaaDepthTolerance, "the TAA depth tolerance must be in (0, 1)");
  }
  if (o.denoise.enabled) {
    const DenoiseParams& d = o.denoise.params;
    if (d.iterations < 0 || d.iterations > kMaxDenoiseIterations)
      throw OptionError(RenderOption::DenoiseIterations,
                        "the denoiser's a-trous passes must be between 0 and " + std::to_string(kMaxDenoiseIterations));
    if (d.directIterations < 1 || d.directIterations > kMaxDenoiseIterations)
      throw OptionError(RenderOption::DenoiseDirectIterations,
                        "the direct signal's a-trous passes must be between 1 and " +
                            std::to_string(kMaxDenoiseIterations) + " (more than the filter's passes count as all)");
    if (!(d.colourAlpha > 0.0f && d.colourAlpha <= 1.0f) || !(d.momentsAlpha > 0.0f && d.momentsAlpha <= 1.0f))
      throw OptionError(RenderOption::DenoiseParameter, "the denoiser's history weights must be in (0, 1]");
    if (!(d.stillPosition >= 0.0f) || !std::isfinite(d.stillPosition) || !(d.stillAngleDegrees >= 0.0f) ||
        !std::isfinite(d.stillAngleDegrees) || !(d.refineAlpha > 0.0f && d.refineAlpha < 1.0f) ||
        !(d.minRadiusFraction > 0.0f && d.minRadiusFraction <= 1.0f))
      throw OptionError(RenderOption::DenoiseParameter,
                        "the refinement's tolerances must be non-negative and finite, its alpha in (0, 1) and its "
                        "least radius fraction in (0, 1]");
    if (!(d.sigmaLuminance > 0.0f) || !std::isfinite(d.sigmaLuminance) || !(d.normalPower >= 0.0f) ||
        !std::isfinite(d.normalPower) || !(d.depthTolerance > 0.0f && d.depthTolerance < 1.0f))
      throw OptionError(RenderOption::DenoiseParameter,
                        "the denoiser's edge-stopping parameters must be positive and finite (depth tolerance in (0, 1))");
  }
  if (o.stereo != StereoMode::Separate && !(o.eyes[0] && o.eyes[1]))
    throw OptionError(RenderOption::Stereo, std::string("stereo reuse (") + stereoModeName(o.stereo) +
                                                ") renders the right eye from the left: it needs both eyes");
}

}  // namespace pvr
