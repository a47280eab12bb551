#pragma once
// A display that is not there: the frame loop's presenter for tests, benchmarks and CI. Views come
// from a scripted head path (cycled) at the rig's size; each frame has a display slot of one
// refresh period, paced like vsync or back to back; the frame's hand-over goes to an optional
// sink (the Vulkan layer's eye transfer, to time the hand-over without a headset).
#include <functional>
#include <vector>

#include "pvr/loop/presenter.h"

namespace pvr {

struct ScriptedView {
  Pose head;
  float gaze[2][2] = {{0.5f, 0.5f}, {0.5f, 0.5f}};
  bool verge = true;
};

struct OffscreenOptions {
  double refreshHz = 90.0;  ///< the display slot: a frame handed over later than 1/refreshHz after its start misses
  bool paced = false;       ///< wait for each slot as a display's vsync would (else start the next frame at once)
  bool deviceImages = true; ///< on the GPU, leave the images there (no host copy) unless the sink needs them
  std::function<void(const PresentedFrame&)> handOver;  ///< called with every rendered frame
};

class OffscreenPresenter : public Presenter {
 public:
  // `path` empty: the rig's own head pose every frame. Throws pvr::Error for a refresh rate
  // that is not positive and finite.
  OffscreenPresenter(StereoRig rig, std::vector<ScriptedView> path, OffscreenOptions options);
  std::string name() const override { return "offscreen"; }
  FrameOutput output(const Renderer& renderer) const override;
  bool waitFrame(FrameRequest& request) override;
  void present(const PresentedFrame& frame) override;
  void requestStop() override { stopped_ = true; }
  uint64_t framesPresented() const { return presented_; }

 private:
  StereoRig rig_;
  std::vector<ScriptedView> path_;
  OffscreenOptions options_;
  LoopClock::duration period_;
  std::optional<LoopClock::time_point> nextSlot_;
  uint64_t frame_ = 0, presented_ = 0;
  bool stopped_ = false;
};

}  // namespace pvr
