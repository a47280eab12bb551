#pragma once
// The frame pipeline, written once over any backend's stages (frame_backend.h):
//
//   validate -> photon trace -> map build -> left eye pass [-> denoise] [-> temporal]
//            -> (scatter) -> (vergence) -> right eye pass [-> denoise] [-> temporal] -> finish
//            -> read back
//
// The left eye goes first: under stereo reuse the right eye reads its surfaces and image, and
// under vergence its depth at the gaze.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pvr/pipeline/frame_backend.h"
#include "pvr/shading/material.h"

namespace pvr {

class FrameRenderer {
 public:
  // `materials`: the scene's, to tell when no surface gathers photons (every material's effect
  // level below gi): those frames trace no photons and build no map. Empty: always traced.
  explicit FrameRenderer(std::unique_ptr<FrameBackend> backend, std::vector<Material> materials = {});

  // Traces photons, builds the map and shades the requested eyes. With images = false the
  // images stay where they were rendered (benchmarks). With options.temporal on, each eye's
  // image is blended with the history of the frames before (kept per eye; an eye whose size
  // changed, or that was skipped, starts again). Throws OptionError for options out of range.
  FrameResult render(const StereoRig& rig, const RenderOptions& options, bool images = true);
  // Forgets the TAA and denoising histories (a cut: the next frame starts again).
  void resetHistory();
  // While a temporal stage (TAA, the denoiser) blends frames, each frame draws new random numbers
  // (photons, shadow rays, sub-pixel positions: the seed mixed with a count of such frames), so
  // that blending averages the noise away rather than keeping one pattern; frames that blend
  // nothing draw the seed's numbers (a still head sees a still image). Off: always the seed's.
  void setFreshNoisePerFrame(bool on) { freshNoise_ = on; }
  // Frames the view has been still before the last one (the denoiser refines while this grows;
  // 0: it moved, or refinement is off).
  int stillFrames() const { return stillFrames_; }
  // The photon radius the last frame gathered with (smaller than asked while refining).
  float gatherRadius() const { return gatherRadius_; }
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
  std::vector<Material> materials_;
  bool mapBuilt_ = false;  ///< the backend has built a photon map (the eye passes' buffers exist)
  bool freshNoise_ = true;
  std::optional<StereoRig> lastRig_;  ///< the last frame's view and options: is this one still?
  RenderOptions lastOptions_;
  int stillFrames_ = 0;
  float gatherRadius_ = 0.0f;
  bool photonsHeld_ = false;  ///< the backend holds photons traced for lastPhotonOptions_
  RenderOptions lastPhotonOptions_;
  int nextPhotonSlot_ = 0;    ///< the rolling map's slice retraced next
  uint32_t blendedFrames_ = 0;         ///< frames rendered with a temporal stage (the noise's frame number)
  bool rendered_[2] = {false, false};  ///< the last frame's
  EyeImage shown_[2] = {EyeImage::Rendered, EyeImage::Rendered};
};

}  // namespace pvr
