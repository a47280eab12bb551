#pragma once
// photonvr's renderers: the frame pipeline (pvr/pipeline) over the backend of your choice, the
// CPU reference (Embree + TBB) or CUDA.
#include <memory>
#include <string>

#include "pvr/pipeline/frame_renderer.h"

namespace pvr {

class Scene;

enum class BackendKind : int { Cpu = 0, Cuda = 1, Auto = 2 };

// "cpu" | "cuda" | "auto"; throws pvr::Error naming --backend otherwise.
BackendKind parseBackendKind(const std::string& text);

// True if this build has the CUDA backend and a CUDA GPU is usable; otherwise `why` says why not.
bool cudaBackendAvailable(std::string* why = nullptr);

// The backend for `kind` (Auto: CUDA if available, else CPU). Throws pvr::Error for Cuda when no
// GPU can be used. The scene must outlive it.
std::unique_ptr<FrameBackend> makeFrameBackend(BackendKind kind, const Scene& scene);
std::unique_ptr<FrameRenderer> makeFrameRenderer(BackendKind kind, const Scene& scene);

// Bytes of the CUDA GPU's memory in use, by every client (the driver's count: total - free); 0
// without a usable GPU. What the backend's own count (FrameResult::deviceBytes) may not see.
size_t gpuMemoryUsedBytes();

// What renderFrame gives back of the eyes' images.
enum class FrameOutput : int {
  HostImages = 0,     ///< copied to host memory (FrameResult::eyes)
  DeviceBuffers = 1,  ///< left in GPU memory (Renderer::deviceImage); the host images stay empty
};

// photonvr for an application: a scene, a headset rig and options, and one call per frame.
class Renderer {
 public:
  // The scene must outlive the renderer. Throws pvr::Error for BackendKind::Cuda without a GPU.
  explicit Renderer(const Scene& scene, BackendKind backend = BackendKind::Auto);

  StereoRig& rig() { return rig_; }  ///< the headset: eye size, IPD, per-eye FOV (starts as the scene's)
  RenderOptions& options() { return options_; }

  // Renders both eyes for a head pose (OpenXR's XrPosef conventions) and the left eye's gaze
  // (image fractions; the right eye fixates what it meets). Throws OptionError for options out of
  // range, pvr::Error for a failure (GPU out of memory included).
  FrameResult renderFrame(const Pose& head, const float gaze[2] = nullptr, FrameOutput output = FrameOutput::HostImages);
  // After a frame: an eye's displayed image in GPU memory (linear RGB floats, row-major, the
  // rig's size), valid until the next frame; null on the CPU backend.
  const Vec3* deviceImage(Eye eye) const { return frames_.deviceImage(eye); }
  const float* deviceInverseDepth(Eye eye) const { return frames_.deviceInverseDepth(eye); }  ///< 1 / view depth, as above
  // The GPU stream the frames run on (cudaStream_t): work queued on it after a frame (a hand-over
  // reading deviceImage) finishes before the next frame writes the images again. Null on the CPU.
  void* deviceStream() const { return frames_.deviceStream(); }
  const StereoRig& rig() const { return rig_; }
  const RenderOptions& options() const { return options_; }
  void resetHistory() { frames_.resetHistory(); }  ///< a cut: TAA starts again
  std::string backendName() const { return frames_.name(); }
  std::string deviceName() const { return frames_.deviceName(); }
  FrameRenderer& frameRenderer() { return frames_; }
  const FrameRenderer& frameRenderer() const { return frames_; }

 private:
  StereoRig rig_;
  RenderOptions options_;
  FrameRenderer frames_;
};

// Counts the pixels with a non-finite component (NaN, +-Inf) in the eyes' images that the last
// frame left in GPU memory (FrameOutput::DeviceBuffers), on the GPU: a check of every frame
// without a readback. Keeps its GPU counters from frame to frame.
class DeviceImageCheck {
 public:
  DeviceImageCheck();
  ~DeviceImageCheck();
  DeviceImageCheck(const DeviceImageCheck&) = delete;
  DeviceImageCheck& operator=(const DeviceImageCheck&) = delete;
  // Per eye; 0 for an eye with no image in GPU memory (the CPU backend, an eye not rendered).
  void nonFinitePixels(const Renderer& renderer, uint64_t counts[2]);
  // The same for a frame renderer's last frame, its eyes `pixels` each: the images shown, or
  // another stage's (EyeImage::Rendered: what the eye pass made, before the denoiser and TAA).
  void nonFinitePixels(const FrameRenderer& frames, size_t pixels, uint64_t counts[2]);
  void nonFinitePixels(FrameRenderer& frames, size_t pixels, EyeImage which, uint64_t counts[2]);

 private:
  void count(const Vec3* const images[2], size_t pixels, void* stream, uint64_t counts[2]);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Where a frame renderer's last frame has non-finite pixels, per eye, read back: how many the eye
// shows (`shown`: the last stage the frame ran) and how many its eye pass rendered, of those how
// many the right eye reused (`reusing`: gather reuse), and the first rendered one (its position,
// value, depth and the left pixel it reused), else the first shown one. For a failure's report.
std::string describeNonFinitePixels(FrameRenderer& frames, EyeImage shown, bool reusing);

}  // namespace pvr
