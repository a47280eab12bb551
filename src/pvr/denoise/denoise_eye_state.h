#pragma once
// One eye's denoising state over either backend's buffers (host vectors, device buffers: anything
// with data()), and the frame's view of it: written once for the HostDenoiser and the GpuDenoiser,
// which only size the buffers their own way and run the passes.
#include <algorithm>

#include "pvr/denoise/svgf.h"
#include "pvr/util/error.h"

namespace pvr {

template <template <class> class Buffer>
struct DenoiseEyeState {
  // What one frame leaves for the next.
  struct History {
    Buffer<ColourVariance> colour[2];
    Buffer<float> moments, length;
    Buffer<DenoiseGuide> guide;
    // A reusing right eye's: per pixel the left pixel whose history it is (svgf.h's
    // DenoiseHistoryView::reusedFrom), from the left eye's history buffer leftHistory.
    Buffer<uint32_t> reusedFrom;
    bool referencesLeft = false;
    int leftHistory = 0;
    uint64_t leftFrames = 0;  ///< the left eye's `frames` then
  };
  History history[2];  ///< ping-pong: the last frame's, and the one being written
  int latest = 0, signals = 0;
  int keptLevels = 0;  ///< levels of this frame kept apart for the right eye (keepLevels; the last signal's)
  bool quarterPhotonPasses = false;  ///< this frame ran them (runsQuarterPhotonPasses)
  uint64_t frames = 0;  ///< frames ended
  bool valid = false;
  EyeCamera camera;
  Buffer<float> depthGradient;
  // Levels 0 .. iterations - 1 (the last pass's output is not kept, but for the photon-map signal's
  // under quarter photon passes: level `iterations`): two buffers (ping-pong by the level's parity)
  // unless keepLevels, where level k has buffer k.
  Buffer<ColourVariance> levels[2][kDenoiseLevels];

  History& next() { return history[latest ^ 1]; }
  // Levels a frame writes of signal s (level 0 also without a-trous passes), and the buffer of level k.
  static int levelCount(const DenoiseParams& params, const DenoiseInputs& in, int s) {
    return std::max(params.iterations, 1) + (s == 1 && runsQuarterPhotonPasses(params, in) ? 1 : 0);
  }
  static int levelBuffer(int k, const DenoiseInputs& in) { return in.keepLevels ? k : k & 1; }
  // Starts a frame: a history of another size or number of signals is not read.
  void begin(const EyeCamera& c, const DenoiseInputs& in) {
    if (valid && (camera.width != c.width || camera.height != c.height || signals != (in.direct ? 2 : 1))) valid = false;
  }
  // Ends the frame: its history becomes the one read next. A reusing right eye's refers to the
  // left eye's history of this frame (`left`, ended before it), which the left eye keeps through
  // its next frame (it writes its other buffer).
  void end(const EyeCamera& c, const DenoiseParams& params, const DenoiseInputs& in, const DenoiseEyeState& left) {
    History& written = next();
    written.referencesLeft = in.reusedFrom != nullptr;
    written.leftHistory = left.latest;
    written.leftFrames = left.frames;
    latest ^= 1;
    ++frames;
    camera = c;
    signals = in.direct ? 2 : 1;
    keptLevels = in.keepLevels ? levelCount(params, in, signals - 1) : 0;
    quarterPhotonPasses = runsQuarterPhotonPasses(params, in);
    valid = true;
  }
};

// The frame's view of one eye's (sized) buffers: the history read (where valid) and written, the
// filter's levels, and for a reusing right eye (in.reusedFrom) the left eye's new history and
// levels of this frame; a left eye that kept none is refused.
template <class State>
DenoiseFrameView denoiseFrameView(Eye eye, const EyeCamera& camera, const DenoiseParams& params, const DenoiseInputs& in,
                                  int stillFrames, State& state, const State& left, Vec3* out) {
  const int signals = in.direct ? 2 : 1;
  DenoiseFrameView v;
  v.camera = camera;
  v.in = in;
  v.params = params;
  v.stillFrames = stillFrames;
  const auto& previous = state.history[state.latest];
  // A history that refers to the left eye's is read only while that is still there: the left eye
  // has ended at most one frame since (it writes its other buffer) at the same size.
  const bool leftKept = !previous.referencesLeft || (left.frames - previous.leftFrames <= 1 && left.camera.width == state.camera.width &&
                                                     left.camera.height == state.camera.height);
  if (state.valid && leftKept) {
    v.history.camera = state.camera;
    for (int s = 0; s < signals; ++s) v.history.colour[s] = previous.colour[s].data();
    v.history.moments = previous.moments.data();
    v.history.length = previous.length.data();
    v.history.guide = previous.guide.data();
    if (previous.referencesLeft) {
      const auto& leftHistory = left.history[previous.leftHistory];
      v.history.reusedFrom = previous.reusedFrom.data();
      for (int s = 0; s < signals; ++s) v.history.sourceColour[s] = leftHistory.colour[s].data();
      v.history.sourceMoments = leftHistory.moments.data();
      v.history.sourceLength = leftHistory.length.data();
    }
  }
  auto& next = state.next();
  v.depthGradient = state.depthGradient.data();
  v.guide = next.guide.data();
  v.moments = next.moments.data();
  v.length = next.length.data();
  for (int s = 0; s < signals; ++s) {
    for (int k = 0; k < State::levelCount(params, in, s); ++k) v.levels[s][k] = state.levels[s][State::levelBuffer(k, in)].data();
    v.historyOut[s] = next.colour[s].data();
  }
  v.out = out;
  v.quarterPhotonPasses = runsQuarterPhotonPasses(params, in);
  if (in.reusedFrom) {
    v.historyReusedFrom = next.reusedFrom.data();
    if (eye != Eye::Right || !left.valid || left.keptLevels < State::levelCount(params, in, signals - 1) ||
        left.signals != signals || left.camera.width != camera.width || left.camera.height != camera.height ||
        !in.sourceDenoised)
      throw Error("the right eye's denoise reuses the left eye's, which did not keep its levels this frame");
    if (left.quarterPhotonPasses != v.quarterPhotonPasses)
      throw Error("the right eye's denoise reuses the left eye's, which ran its photon-map passes on other pixels");
    const auto& shared = left.history[left.latest];
    for (int s = 0; s < signals; ++s) {
      for (int k = 0; k < State::levelCount(params, in, s); ++k) v.source.levels[s][k] = left.levels[s][k].data();
    }
    v.source.moments = shared.moments.data();
    v.source.length = shared.length.data();
    v.source.quarterPhotonPasses = left.quarterPhotonPasses;
    v.source.guide = shared.guide.data();
  }
  return v;
}

}  // namespace pvr
