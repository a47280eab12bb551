#pragma once
// The frame pipeline's stages on the GPU: photon tracing, the hash-grid or kd-tree build, the
// paper's single / hybrid / shared-memory eye passes and our cell-sorted one, foveated passes,
// stereo scatter and TAA, with CUDA-event stage times. No CUDA header is needed to use it.
#include <memory>
#include <string>
#include <vector>

#include "pvr/accel/bvh.h"
#include "pvr/pipeline/frame_renderer.h"
#include "pvr/photon/gather.h"
#include "pvr/photon/photon.h"

struct CUstream_st;  // cudaStream_t

namespace pvr {

class Scene;
class WideBvh;
namespace cuda {
struct DeviceScene;
}

// True if a CUDA GPU can be used; otherwise `why` says why not in one line.
bool cudaDeviceUsable(std::string* why);

struct GpuHashGridCopy {
  std::vector<Photon> photons;
  std::vector<uint32_t> cellStart, sortedToInput;
};

struct GpuKdTreeCopy {
  std::vector<Photon> photons;  ///< in node order
  std::vector<uint8_t> axes;
  std::vector<uint32_t> nodeToInput;
};

// The BVH the photon pass traces: frames use the binary one, which the eye kernels trace too; the
// 8-wide one traced a cathedral's diffuse rays 1.2x as fast (bench --suite rays), and its photon
// pass is measured beside the binary's in that suite's photon rows before frames take it.
enum class PhotonPassBvh { Binary, Wide };

class CudaFrameBackend : public FrameBackend {
 public:
  // Throws pvr::Error if no GPU can be used, or the scene does not fit on it.
  explicit CudaFrameBackend(const Scene& scene);
  ~CudaFrameBackend() override;
  std::string name() const override { return "cuda"; }
  std::string deviceName() const override;
  StageClock& clock() override;

  size_t tracePhotons(const PhotonTraceParams& params, int slot, int slots) override;
  size_t buildPhotonMap(PhotonMapKind kind, float radius) override;
  void rasterizePrimary(const EyeCamera eyes[2]) override;
  void scatter(const EyeCamera& source, const EyeCamera& target) override;
  void renderEye(const EyePass& pass) override;
  float inverseDepthAt(Eye eye, size_t pixel) override;
  void denoise(const EyePass& pass, const DenoiseParams& params) override;
  void resolveTemporal(const TemporalPass& pass) override;
  void forgetHistory(Eye eye) override;
  void forgetDenoiseHistory(Eye eye) override;
  FrameCounters finishFrame() override;
  void readEye(Eye eye, const EyeReadback& what, EyeResult& out) override;
  const Vec3* deviceImage(Eye eye, EyeImage which) const override;
  const float* deviceInverseDepth(Eye eye) const override;
  void* deviceStream() const override;

  // Tools for tests and benchmarks.
  // Which BVH tracePhotons traces from now on. The 8-wide one is uploaded at first use: `built`
  // where given (the scene's, as WideBvh::build makes it), else built here.
  void setPhotonPassBvh(PhotonPassBvh bvh, const WideBvh* built = nullptr);
  std::vector<Photon> tracePhotonsToHost(const PhotonTraceParams& params);
  // The photons of the map the last frame estimated from, and an eye pass's direct part (shadow
  // rays and emission: the denoiser's guide) in device memory: where a pixel's radiance came from.
  std::vector<Photon> mapPhotonsToHost();
  const Vec3* deviceDirect(Eye eye) const;
  // Pixel `pixel`'s gather point as the last full-resolution eye pass stored it for its density
  // estimate (its last sample; under stereo the right eye's): what the estimate started from.
  GatherPoint gatherPointToHost(size_t pixel);
  // Builds the hash grid over `photons` on the GPU `repeats` times; returns the median build time
  // in ms (CUDA events, cell keys to gathered photons; the photons' bounds are given, as the
  // tracer reduces them while tracing) and optionally the grid.
  double buildHashGrid(const std::vector<Photon>& photons, float radius, int repeats, GpuHashGridCopy* copy = nullptr);
  // Builds the kd-tree over `photons` on the GPU `repeats` times; returns the median build time
  // in ms (CUDA events) and optionally the tree.
  double buildKdTree(const std::vector<Photon>& photons, int repeats, GpuKdTreeCopy* copy = nullptr);
  const BvhBuildStats& bvhStats() const;
  size_t deviceBytes() const;  ///< GPU memory held by this backend now
  const cuda::DeviceScene& deviceScene() const;
  CUstream_st* stream() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A frame renderer on the CUDA backend; throws pvr::Error if no GPU can be used.
FrameRenderer makeCudaFrameRenderer(const Scene& scene);

// The current GPU's memory in use by every client (cudaMemGetInfo: total - free); 0 on failure.
size_t cudaDeviceMemoryUsedBytes();

}  // namespace pvr
