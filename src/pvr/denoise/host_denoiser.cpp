#include "pvr/denoise/host_denoiser.h"

#include <algorithm>
#include <atomic>

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
  if (state.valid && (state.camera.width != camera.width || state.camera.height != camera.height || state.signals != signals))
    state.valid = false;
  const History& previous = state.history[state.latest];
  History& next = state.history[state.latest ^ 1];
  const int levels = in.keepLevels ? params.iterations + 1 : 2;
  for (int s = 0; s < signals; ++s) {
    next.colour[s].resize(pixels);
    for (int k = 0; k < levels; ++k) state.levels[s][k].resize(pixels);
  }
  next.moments.resize(4 * pixels);
  next.length.resize(pixels);
  next.guide.resize(pixels);
  state.depthGradient.resize(2 * pixels);
  out = Image(camera.width, camera.height);

  DenoiseFrameView v;
  v.camera = camera;
  v.in = in;
  v.params = params;
  v.stillFrames = stillFrames;
  if (state.valid) {
    v.history.camera = state.camera;
    for (int s = 0; s < signals; ++s) v.history.colour[s] = previous.colour[s].data();
    v.history.moments = previous.moments.data();
    v.history.length = previous.length.data();
    v.history.guide = previous.guide.data();
  }
  v.depthGradient = state.depthGradient.data();
  v.guide = next.guide.data();
  v.moments = next.moments.data();
  v.length = next.length.data();
  for (int s = 0; s < signals; ++s) {
    for (int k = 0; k < kDenoiseLevels; ++k) v.filtered[s][k] = state.levels[s][in.keepLevels ? std::min(k, levels - 1) : k & 1].data();
    v.historyOut[s] = next.colour[s].data();
  }
  v.out = out.pixels.data();
  if (in.reusedFrom) {
    const EyeState& left = eyes_[int(Eye::Left)];
    if (eye != Eye::Right || !left.valid || left.keptLevels < params.iterations + 1 || left.signals != signals ||
        !in.sourceDenoised)
      throw Error("the right eye's denoise reuses the left eye's, which did not keep its levels this frame");
    const History& shared = left.history[left.latest];
    for (int s = 0; s < signals; ++s) {
      v.source.history[s] = shared.colour[s].data();
      for (int k = 0; k <= params.iterations; ++k) v.source.levels[s][k] = left.levels[s][k].data();
    }
    v.source.moments = shared.moments.data();
    v.source.length = shared.length.data();
  }

  std::atomic<size_t> used{0};
  forEachPixel("denoise accumulate", camera, [&](int x, int y) {
    if (accumulateDenoisePixel(v, x, y)) used.fetch_add(1, std::memory_order_relaxed);
  });
  // The later passes run over the pixels the eye filters (svgf.h's filtersPixel).
  auto forEachFiltered = [&](const char* what, const auto& body) {
    forEachPixel(what, camera, [&](int x, int y) {
      if (filtersPixel(v, denoisePixel(camera, x, y))) body(x, y);
    });
  };
  if (params.iterations == 0) {
    forEachFiltered("denoise remodulate", [&](int x, int y) { remodulateAccumulated(v, x, y); });
  } else {
    forEachFiltered("denoise variance", [&](int x, int y) { estimateDenoiseVariance(v, x, y); });
    for (int i = 0; i < params.iterations; ++i) {
      const AtrousLevels levels = atrousLevels(v, i);
      forEachFiltered("denoise a-trous", [&](int x, int y) { atrousDenoisePixel(v, i, levels, x, y); });
    }
  }
  state.latest ^= 1;
  state.camera = camera;
  state.signals = signals;
  state.keptLevels = in.keepLevels ? levels : 0;
  state.valid = true;
  return used;
}

}  // namespace pvr
