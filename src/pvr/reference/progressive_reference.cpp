#include "pvr/reference/progressive_reference.h"

#include <cmath>
#include <limits>

#include "pvr/image/image_compare.h"
#include "pvr/util/error.h"
#include "pvr/util/parallel_for.h"
#include "pvr/util/rng.h"

namespace pvr {

ProgressiveReference::ProgressiveReference(FrameRenderer& renderer, const StereoRig& rig, const RenderOptions& options,
                                           const ReferenceSettings& settings)
    : renderer_(renderer), rig_(rig), options_(options), settings_(settings) {
  if (!(settings.alpha > 0.0f && settings.alpha < 1.0f))
    throw Error("the reference's alpha must be between 0 and 1 (exclusive), got " + std::to_string(settings.alpha));
  options_.stereo = StereoMode::Separate;
  options_.density = DensityScheme::PerPixel;  // an estimate per pixel: no cell's blur in the reference
  options_.primary = PrimaryVisibility::Rays;   // the reference traces every ray it uses
  options_.gather.overrideEffects = true;      // the whole light transport, whatever the materials' effect levels
  options_.gather.effects = EffectLevel::Gi;
  options_.foveation.mask = nullptr;
  options_.temporal.enabled = false;
  options_.denoise.enabled = false;
  options_.gather.jitterFirstSample = settings.boxFilter;
  validateOptions(options_, rig_);
  const size_t values = size_t(rig_.width) * rig_.height * 3;
  for (int e = 0; e < 2; ++e)
    if (options_.eyes[e]) sum_[e].assign(values, 0.0), sumSquares_[e].assign(values, 0.0);
}

float ProgressiveReference::radiusOfPass(int pass) const {
  return progressiveRadius(options_.gather.density.radius, pass, settings_.alpha);
}

void ProgressiveReference::addPass() {
  if (passes_ >= kMaxReferencePasses) throw Error("the reference is at its limit of " + std::to_string(kMaxReferencePasses) + " passes");
  RenderOptions pass = options_;
  pass.gather.density.radius = radiusOfPass(passes_);
  pass.gather.seed = hashCombine(options_.gather.seed, uint32_t(passes_));
  pass.gather.sampling = PixelSampling::White;  // independent passes: the error estimate assumes it
  FrameResult frame = renderer_.render(rig_, pass);
  frameMs_ += frame.timings.totalMs();
  for (int e = 0; e < 2; ++e) {
    if (!options_.eyes[e]) continue;
    const std::vector<Vec3>& pixels = frame.eyes[e].image.pixels;
    double* sum = sum_[e].data();
    double* squares = sumSquares_[e].data();
    parallelFor("reference accumulation", pixels.size(), 4096, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i)
        for (int c = 0; c < 3; ++c) {
          double v = pixels[i][c];
          sum[3 * i + c] += v;
          squares[3 * i + c] += v * v;
        }
    });
  }
  ++passes_;
}

Image ProgressiveReference::image(Eye eye) const {
  const int e = int(eye);
  if (!options_.eyes[e]) return Image();
  Image out(rig_.width, rig_.height);
  const double scale = passes_ > 0 ? 1.0 / passes_ : 0.0;
  for (size_t i = 0; i < out.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) out.pixels[i][c] = float(sum_[e][3 * i + c] * scale);
  return out;
}

double ProgressiveReference::estimatedRelMse(Eye eye, const std::vector<uint8_t>& mask) const {
  const int e = int(eye);
  if (!options_.eyes[e] || passes_ < 2) return std::numeric_limits<double>::infinity();
  if (!mask.empty() && mask.size() * 3 != sum_[e].size()) throw Error("the reference's error mask has the wrong size");
  const double n = passes_;
  double total = 0;
  size_t counted = 0;
  for (size_t i = 0; i < sum_[e].size(); ++i) {
    if (!mask.empty() && !mask[i / 3]) continue;
    ++counted;
    double mean = sum_[e][i] / n;
    double variance = std::max(sumSquares_[e][i] / n - mean * mean, 0.0) * n / (n - 1.0);
    total += variance / n / (mean * mean + kRelMseRegulariser);
  }
  return counted ? total / double(counted) : 0.0;
}

}  // namespace pvr
