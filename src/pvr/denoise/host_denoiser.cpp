#include "pvr/denoise/host_denoiser.h"

#include <algorithm>
#include <atomic>
#include <limits>

#include "pvr/util/error.h"
#include "pvr/util/parallel_for.h"

namespace pvr {
namespace {

template <class Body>
void forEachPixel(const char* what, const EyeCamera& camera, const Body& body) {
  parallelFor(what, size_t(camera.height), 8, [&](size_t begin, size_t end) {
    for (int y = int(begin); y < int(end); ++y)
      for (int x = 0; x < camera.width; ++x) body(x, y);
  });
}

}  // namespace

size_t HostDenoiser::denoise(Eye eye, const EyeCamera& camera, const DenoiseParams& params, const DenoiseInputs& in,
                             Image& out, int stillFrames) {
  if (!in.image || !in.inverseDepth) throw Error("the denoiser needs the eye's image and its per-pixel depth");
  EyeState& state = eyes_[int(eye)];
  const size_t pixels = size_t(camera.width) * camera.height;
  const int signals = in.direct ? 2 : 1;
  state.begin(camera, in);
  EyeState::History& next = state.next();
  // What the passes write, sized (and under poisonUnwritten filled with NaN first).
  const float nan = std::numeric_limits<float>::quiet_NaN();
  ColourVariance unwritten;
  unwritten.colour = Vec3(nan), unwritten.variance = nan;
  auto written = [&](auto& buffer, size_t n, const auto& poison) {
    buffer.resize(n);
    if (poison_) std::fill(buffer.begin(), buffer.end(), poison);
  };
  for (int s = 0; s < signals; ++s) {
    written(next.colour[s], pixels, unwritten);
    for (int k = 0; k < EyeState::levelCount(params, in, s); ++k) written(state.levels[s][EyeState::levelBuffer(k, in)], pixels, unwritten);
  }
  written(next.moments, 4 * pixels, nan);
  written(next.length, pixels, nan);
  next.guide.resize(pixels);
  if (in.reusedFrom) next.reusedFrom.resize(pixels);
  state.depthGradient.resize(2 * pixels);
  out = Image(camera.width, camera.height);
  const DenoiseFrameView v =
      denoiseFrameView(eye, camera, params, in, stillFrames, state, eyes_[int(Eye::Left)], out.pixels.data());

  std::atomic<size_t> used{0};
  forEachPixel("denoise accumulate", camera, [&](int x, int y) {
    if (accumulateDenoisePixel(v, x, y)) used.fetch_add(1, std::memory_order_relaxed);
  });
  // The later passes run over the pixels the eye filters (svgf.h's filtersPixel).
  auto forEachFiltered = [&](const char* what, const auto& body, AtrousPixels which = AtrousPixels::All) {
    forEachPixel(what, camera, [&](int x, int y) {
      if (atrousRunsAt(which, x, y) && filtersPixel(v, denoisePixel(camera, x, y))) body(x, y);
    });
  };
  if (params.iterations == 0) {
    forEachFiltered("denoise remodulate", [&](int x, int y) { remodulateAccumulated(v, x, y); });
  } else {
    forEachFiltered("denoise variance", [&](int x, int y) { estimateDenoiseVariance(v, x, y); });
    for (int i = 0; i < params.iterations; ++i) {
      if (i == 0 || !v.quarterPhotonPasses) {
        const AtrousLevels levels = atrousLevels(v, i);
        forEachFiltered("denoise a-trous", [&](int x, int y) { atrousDenoisePixel(v, i, levels, x, y); });
        continue;
      }
      // The even pixels first: the odd ones' last pass interpolates what theirs wrote.
      for (AtrousPixels half : {AtrousPixels::Even, AtrousPixels::Odd}) {
        const AtrousLevels levels = atrousLevels(v, i, half);
        if (!levels.runs()) continue;
        forEachFiltered("denoise a-trous", [&](int x, int y) { atrousDenoisePixelQuarter(v, i, levels, x, y); }, half);
      }
    }
  }
  state.end(camera, params, in, eyes_[int(Eye::Left)]);
  return used;
}

}  // namespace pvr
