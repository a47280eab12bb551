#include "pvr/loop/offscreen_presenter.h"

#include <cmath>
#include <thread>

#include "pvr/foveation/gaze.h"
#include "pvr/util/error.h"

namespace pvr {

OffscreenPresenter::OffscreenPresenter(StereoRig rig, std::vector<ScriptedView> path, OffscreenOptions options)
    : rig_(rig), path_(std::move(path)), options_(std::move(options)) {
  if (!(options_.refreshHz > 0.0) || !std::isfinite(options_.refreshHz) || options_.refreshHz > 10000.0)
    throw Error("the display refresh rate must be a number of hertz in (0, 10000]");
  period_ = std::chrono::duration_cast<LoopClock::duration>(std::chrono::duration<double>(1.0 / options_.refreshHz));
}

FrameOutput OffscreenPresenter::output(const Renderer& renderer) const {
  return options_.deviceImages && renderer.backendName() == "cuda" ? FrameOutput::DeviceBuffers : FrameOutput::HostImages;
}

bool OffscreenPresenter::waitFrame(FrameRequest& request) {
  if (stopped_) return false;
  LoopClock::time_point now = LoopClock::now();
  LoopClock::time_point slot = now;
  if (options_.paced && nextSlot_) {
    slot = *nextSlot_;
    while (slot + period_ < now) slot += period_;  // a late frame takes the next slot, as a display would
    std::this_thread::sleep_until(slot);
  }
  nextSlot_ = slot + period_;
  request.rig = rig_;
  if (!path_.empty()) {
    const ScriptedView& view = path_[frame_ % path_.size()];
    request.rig.head = view.head;
    copyGaze(view, request);
  }
  request.shouldRender = true;
  request.deadline = slot + period_;
  request.displayPeriodMs = std::chrono::duration<double, std::milli>(period_).count();
  ++frame_;
  return true;
}

void OffscreenPresenter::present(const PresentedFrame& frame) {
  if (frame.result && options_.handOver) options_.handOver(frame);
  ++presented_;
}

}  // namespace pvr
