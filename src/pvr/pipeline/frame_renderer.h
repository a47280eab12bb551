#pragma once
// The frame pipeline, written once over any backend's stages (frame_backend.h):
//
//   validate -> photon trace -> map build -> left eye pass [-> temporal]
//            -> (scatter) -> (vergence) -> right eye pass [-> temporal] -> finish -> read back
//
// The left eye goes first: under stereo reuse the right eye reads its surfaces and image, and
// under vergence its depth at the gaze.
#include <memory>
#include <string>

#include "pvr/pipeline/frame_backend.h"

namespace pvr {

class FrameRenderer {
 public:
  explicit FrameRenderer(std::unique_ptr<FrameBackend> backend);

  // Traces photons, builds the map and shades the requested eyes. With images = false the
  // images stay where they were rendered (benchmarks). With options.temporal on, each eye's
  // image is blended with the history of the frames before (kept per eye; an eye whose size
  // changed, or that was skipped, starts again). Throws OptionError for options out of range.
  FrameResult render(const StereoRig& rig, const RenderOptions& options, bool images = true);
  // Forgets the TAA history (a cut: the next frame is shown as rendered).
  void resetHistory();
  // The last frame's displayed image of an eye in GPU memory (linear RGB, row-major, the rig's
  // size), valid until the next frame; null on the CPU backend or for an eye not rendered.
  const Vec3* deviceImage(Eye eye) const;
  // The same frame's per-pixel 1 / view depth (0: nothing hit) in GPU memory; null as above.
  const float* deviceInverseDepth(Eye eye) const;
  void* deviceStream() const { return backend_->deviceStream(); }  ///< cudaStream_t of the frames; null on the CPU

  std::string name() const { return backend_->name(); }  ///< "cpu" or "cuda"
  std::string deviceName() const { return backend_->deviceName(); }
  FrameBackend& backend() { return *backend_; }
  // The backend as its own type (tests and benchmarks reach its extra tools); throws if it is not one.
  template <class B>
  B& backendAs() {
    if (auto* b = dynamic_cast<B*>(backend_.get())) return *b;
    throw Error("the " + backend_->name() + " backend is not the one asked for");
  }

 private:
  std::unique_ptr<FrameBackend> backend_;
  bool rendered_[2] = {false, false}, displayed_[2] = {false, false};  ///< the last frame's
};

}  // namespace pvr
