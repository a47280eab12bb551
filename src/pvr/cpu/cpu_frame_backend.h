#pragma once
// The frame pipeline's stages on the CPU reference backend: host buffers between the stages,
// the work in CpuBackend's parallel loops, times on the host clock.
#include <memory>
#include <vector>

#include "pvr/cpu/cpu_backend.h"
#include "pvr/denoise/host_denoiser.h"
#include "pvr/pipeline/frame_renderer.h"
#include "pvr/temporal/taa_history.h"

namespace pvr {

class VulkanContext;
class GBufferRaster;

class CpuFrameBackend : public FrameBackend {
 public:
  explicit CpuFrameBackend(const Scene& scene);
  ~CpuFrameBackend() override;
  std::string name() const override { return "cpu"; }
  std::string deviceName() const override;
  StageClock& clock() override { return clock_; }

  size_t tracePhotons(const PhotonTraceParams& params, int slot, int slots) override;
  size_t buildPhotonMap(PhotonMapKind kind, float radius) override;
  // The G-buffer pre-pass on the Vulkan device it finds (a GPU, or lavapipe), read from host memory.
  void rasterizePrimary(const EyeCamera eyes[2]) override;
  void scatter(const EyeCamera& source, const EyeCamera& target) override;
  void renderEye(const EyePass& pass) override;
  float inverseDepthAt(Eye eye, size_t pixel) override { return eyes_[int(eye)].inverseDepth.at(pixel); }
  void denoise(const EyePass& pass, const DenoiseParams& params) override;
  void resolveTemporal(const TemporalPass& pass) override;
  void forgetHistory(Eye eye) override { history_[int(eye)].valid = false; }
  void forgetDenoiseHistory(Eye eye) override { denoiser_.forget(eye); }
  FrameCounters finishFrame() override;
  void readEye(Eye eye, const EyeReadback& what, EyeResult& out) override;

  const CpuBackend& backend() const { return backend_; }

 private:
  // One eye's buffers between its stages.
  struct EyeBuffers {
    Image rendered, denoised, displayed;
    std::vector<float> inverseDepth, sampleSpacing;
    std::vector<uint32_t> firstPrim, reusedFrom;
    std::vector<Vec3> emitted, direct, albedo, normal;  ///< the denoiser's guides (full resolution)
  };
  template <class Map>
  void renderEyeWith(const EyePass& pass, const Map& map);

  CpuBackend backend_;
  HostStageClock clock_;
  std::vector<Photon> photons_;                   ///< what the map is built over
  std::vector<std::vector<Photon>> photonSlots_;  ///< a rolling map's slices (empty: one trace)
  PhotonMapKind mapKind_ = PhotonMapKind::HashGrid;
  HashGrid grid_;
  KdTree tree_;
  HostSurfaceCache cache_;
  bool cacheStale_ = true;  ///< a new photon map: the cache starts again at its next use
  size_t lastCacheCells_ = 0;
  std::vector<SurfaceRecord> sourceSurfaces_;
  std::vector<uint64_t> scattered_;
  std::vector<PixelSample> samples_;
  std::vector<PixelGuide> guides_;
  EyeBuffers eyes_[2];
  TaaHistory history_[2];
  HostDenoiser denoiser_;
  FrameCounters counters_;
  std::unique_ptr<VulkanContext> rasterVulkan_;  ///< made at the first pre-pass
  std::unique_ptr<GBufferRaster> raster_;
  bool rasterised_ = false;  ///< this frame's pre-pass ran
};

// A frame renderer on the CPU reference backend.
inline FrameRenderer makeCpuFrameRenderer(const Scene& scene) {
  return FrameRenderer(std::make_unique<CpuFrameBackend>(scene), scene.materials());
}

}  // namespace pvr
