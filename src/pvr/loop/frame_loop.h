#pragma once
// The frame loop shared by every presenter: pose and gaze in, both eyes rendered, images out,
// per-frame statistics kept. One loop; the presenter decides where the frames go.
#include <atomic>
#include <cstdint>

#include "pvr/control/budget_controller.h"
#include "pvr/loop/frame_stats.h"
#include "pvr/loop/presenter.h"

namespace pvr {

struct FrameLoopOptions {
  uint64_t maxFrames = 0;                    ///< rendered frames before stopping (0: until the presenter ends)
  uint64_t warmupFrames = 0;                 ///< rendered but not counted in the statistics
  const std::atomic<bool>* stop = nullptr;   ///< set (by a signal handler) to end the loop cleanly
  // Chooses each frame's photons, radius, foveation, denoiser and effect levels to hold its
  // budget (the frame's work, FrameRecord::cpuMs); its decisions go into the stats. Null: the
  // renderer's options as they are (and as the presenter adjusts them).
  BudgetController* controller = nullptr;
};

class FrameLoop {
 public:
  FrameLoop(Renderer& renderer, Presenter& presenter) : renderer_(renderer), presenter_(presenter) {}
  // Runs until the presenter ends; asks it to stop after maxFrames or when *stop is set.
  // Throws what the renderer or presenter throws (OptionError, pvr::Error).
  FrameStats run(const FrameLoopOptions& options);

 private:
  Renderer& renderer_;
  Presenter& presenter_;
};

}  // namespace pvr
