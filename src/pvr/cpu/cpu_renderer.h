#pragma once
// Frames on the CPU reference backend.
#include "pvr/cpu/cpu_backend.h"
#include "pvr/frame/frame.h"
#include "pvr/temporal/taa_history.h"

namespace pvr {

// One frame as rendered (no TAA: that needs the renderer's history).
FrameResult renderFrame(const CpuBackend& backend, const StereoRig& rig, const RenderOptions& options);

class CpuFrameRenderer : public FrameRenderer {
 public:
  explicit CpuFrameRenderer(const Scene& scene) : backend_(scene) {}
  FrameResult render(const StereoRig& rig, const RenderOptions& options, bool images = true) override;
  void resetHistory() override {
    for (TaaHistory& h : history_) h.valid = false;
  }
  std::string name() const override { return "cpu"; }
  std::string deviceName() const override;
  const CpuBackend& backend() const { return backend_; }

 private:
  CpuBackend backend_;
  TaaHistory history_[2];
};

}  // namespace pvr
