#pragma once
// Frames on the CPU reference backend.
#include "pvr/cpu/cpu_backend.h"
#include "pvr/frame/frame.h"

namespace pvr {

FrameResult renderFrame(const CpuBackend& backend, const StereoRig& rig, const RenderOptions& options);

class CpuFrameRenderer : public FrameRenderer {
 public:
  explicit CpuFrameRenderer(const Scene& scene) : backend_(scene) {}
  FrameResult render(const StereoRig& rig, const RenderOptions& options, bool images = true) override {
    return renderFrame(backend_, rig, options);
  }
  std::string name() const override { return "cpu"; }
  std::string deviceName() const override;
  const CpuBackend& backend() const { return backend_; }

 private:
  CpuBackend backend_;
};

}  // namespace pvr
