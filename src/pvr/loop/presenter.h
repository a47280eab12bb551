#pragma once
// Where the frame loop's images go: a headset (OpenXR), a desktop window, or nowhere
// (offscreen, for tests and benchmarks). The loop asks the presenter for the next frame's views,
// renders them and hands the result back; the renderer never knows which presenter it serves.
#include <chrono>
#include <optional>
#include <string>

#include "pvr/render/renderer.h"

namespace pvr {

using LoopClock = std::chrono::steady_clock;  // CLOCK_MONOTONIC on Linux, as OpenXR's timespec time

// What the presenter wants rendered this frame.
struct FrameRequest {
  StereoRig rig;               ///< both eyes' poses, FOVs and size (scene units)
  float gaze[2][2] = {{0.5f, 0.5f}, {0.5f, 0.5f}};  ///< per eye, image fractions
  bool verge = true;           ///< the right eye fixates what the left eye's gaze meets
  bool gazeTracked = false;    ///< the gaze came from an eye tracker this frame
  bool shouldRender = true;    ///< false: the display shows nothing of it (hand back an empty frame)
  std::optional<LoopClock::time_point> deadline;  ///< the hand-over must be done by then
  // The display's frame period (OpenXR's predicted display period, the monitor's refresh, the
  // offscreen slot), when the presenter knows it: `--budget-ms display` follows it.
  std::optional<double> displayPeriodMs;
};

// A rendered frame as handed to the presenter.
struct PresentedFrame {
  const FrameRequest& request;
  const FrameResult* result = nullptr;  ///< null when request.shouldRender was false
  const Renderer& renderer;             ///< deviceImage / deviceInverseDepth when on the GPU
  bool onDevice = false;                ///< the images are in GPU memory, not in result->eyes
};

class Presenter {
 public:
  virtual ~Presenter() = default;
  virtual std::string name() const = 0;
  // Where the presenter takes the images from: host images (CPU backend, or a presenter that
  // copies) or GPU buffers left by the CUDA backend.
  virtual FrameOutput output(const Renderer& renderer) const = 0;
  // Blocks until the display wants the next frame and fills `request` (it holds the previous
  // frame's values on entry). False: the presenter is done (session over, window closed).
  virtual bool waitFrame(FrameRequest& request) = 0;
  // Hands the frame to the display. Called once after every waitFrame that returned true.
  virtual void present(const PresentedFrame& frame) = 0;
  // Asks the presenter to end (Ctrl-C, frame count reached); waitFrame returns false once done.
  virtual void requestStop() = 0;
  // Options the display changed (the viewer's panel); applied before the next frame.
  virtual void adjustOptions(RenderOptions& options) {}
};

}  // namespace pvr
