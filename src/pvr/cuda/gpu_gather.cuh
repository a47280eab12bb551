#pragma once
// The eye pass on the GPU: the paper's three kernel schemes over the shared gathering code,
// and the ray-throughput kernels of the benchmark.
#include <memory>
#include <vector>

#include "pvr/cuda/gpu_scene.cuh"
#include "pvr/foveation/reconstruct.h"
#include "pvr/frame/frame.h"

namespace pvr::cuda {

// The photon map the eye pass reads: exactly one of the two is set.
struct DeviceMap {
  const HashGridView* grid = nullptr;
  const KdTreeView* tree = nullptr;
};

// Events around each sample's eye-ray and density stages (grow-only, reused across frames).
struct EyeTimers {
  std::vector<std::unique_ptr<EventTimer>> rays, density;
  int used = 0;
  void prepare(int samples) {
    while (int(rays.size()) < samples) {
      rays.push_back(std::make_unique<EventTimer>());
      density.push_back(std::make_unique<EventTimer>());
    }
    used = samples;
  }
  // Waits for the events; sums over the samples.
  double raysMs() const {
    double t = 0;
    for (int s = 0; s < used; ++s) t += rays[s]->ms();
    return t;
  }
  double densityMs() const {
    double t = 0;
    for (int s = 0; s < used; ++s) t += density[s]->ms();
    return t;
  }
};

// Per-pixel outputs of an eye pass besides its image (null pointers are not written).
struct EyeOutputs {
  Vec3* image = nullptr;
  uint32_t* firstPrim = nullptr;
  float* inverseDepth = nullptr;
  SurfaceRecord* surfaces = nullptr;  ///< the left eye under stereo reuse
  uint32_t* reusedFrom = nullptr;     ///< the right eye under stereo reuse
  unsigned* reusedCount = nullptr;    ///< with reusedFrom: pixels that took the left eye's shading
};

// A foveation mask on the device, its triangles also listed by size for the raster: a thread
// each for the small ones (the fovea's, a pixel or two), a warp each for the rest.
struct DeviceMaskView {
  const MaskPoint* offsets = nullptr;
  const uint32_t* triangles = nullptr;  ///< 3 per triangle
  uint32_t vertexCount = 0, triangleCount = 0;
  const uint32_t* smallTriangles = nullptr;  ///< at most kSmallTrianglePixels candidate pixels
  const uint32_t* largeTriangles = nullptr;
  uint32_t smallCount = 0, largeCount = 0;
};
constexpr int kSmallTrianglePixels = 8;

class GpuGather {
 public:
  // Shades one eye into image(eye), firstPrim(eye) and inverseDepth(eye); times its stages on `timers`. Under stereo
  // reuse (options.stereo) the left eye records its surfaces and the right eye, rendered after
  // it (and after scatter() for Scatter), takes the left eye's shading where it may.
  void renderEye(const DeviceScene& scene, DeviceMap map, const RenderOptions& options, const StereoRig& rig,
                 Eye eye, cudaStream_t stream, EyeTimers& timers);
  // Foveated: lists the mask's vertices in use for the eye's gaze, shades them (eye rays, then
  // estimates) and rasterizes the eye's image, depth and sample spacing from them (timed on
  // `reconstruct`); firstPrim(eye) is not written.
  void renderFoveatedEye(const DeviceScene& scene, DeviceMap map, const RenderOptions& options, const StereoRig& rig,
                         Eye eye, const DeviceMaskView& mask, cudaStream_t stream, EyeTimers& timers,
                         EventTimer& reconstruct);
  // The number of vertices the last foveated pass of each eye shaded, copied when the stream gets there.
  void downloadShadedVertices(uint32_t host[2], cudaStream_t stream) const;
  // Scatter: projects the left eye's recorded surfaces into the right image (after the left eye).
  void scatter(const DeviceScene& scene, const StereoRig& rig, cudaStream_t stream);
  const Vec3* image(Eye e) const { return images_[int(e)].data(); }
  const uint32_t* firstPrim(Eye e) const { return firstPrim_[int(e)].data(); }
  const float* inverseDepth(Eye e) const { return inverseDepth_[int(e)].data(); }
  const float* sampleSpacing(Eye e) const { return sampleSpacing_[int(e)].data(); }  ///< foveated only
  const uint32_t* reusedFrom() const { return reusedFrom_.data(); }
  // The right eye's reused-pixel count, copied to the host when the stream reaches it.
  void downloadReusedCount(unsigned* host, cudaStream_t stream) const;
  size_t memoryBytes() const;

 private:
  // Sets up `eye`'s part in stereo reuse (options.stereo): the left eye's surface records in
  // `out`, or the right eye's view of them, with its reuse outputs in `out`.
  StereoReuseView prepareReuse(const RenderOptions& options, const StereoRig& rig, Eye eye, cudaStream_t stream,
                               EyeOutputs& out);

  DeviceBuffer<Vec3> images_[2];
  DeviceBuffer<uint32_t> firstPrim_[2];
  DeviceBuffer<float> inverseDepth_[2], sampleSpacing_[2];
  DeviceBuffer<SurfaceRecord> surfaces_;
  DeviceBuffer<uint64_t> scattered_;
  DeviceBuffer<uint32_t> reusedFrom_;
  DeviceBuffer<unsigned> reusedCount_;
  DeviceBuffer<uint32_t> estimateList_, estimateCount_;  ///< the right eye's points still to estimate
  DeviceBuffer<uint8_t> vertexUsed_;
  DeviceBuffer<uint32_t> vertexList_, vertexCount_;  ///< foveated: the vertices shaded (count per eye)
  DeviceBuffer<GatherPoint> vertexPoints_;
  DeviceBuffer<Vec3> vertexColours_;
  DeviceBuffer<float> vertexInverseDepths_;
  DeviceBuffer<GatherPoint> points_;
  DeviceBuffer<uint32_t> sortKeys_[2], sortValues_[2];
  DeviceBuffer<unsigned char> temp_;
};

// Rays per second through the CUDA traversal, both eyes' pixels: primary rays, shadow rays to a
// light sample from each primary hit, and cosine-distributed diffuse rays from each primary hit.
struct RayThroughput {
  uint64_t primaryRays = 0, shadowRays = 0, diffuseRays = 0;
  double primaryMs = 0, shadowMs = 0, diffuseMs = 0;  ///< medians over the repeats
  std::vector<Hit> primaryHits;  ///< left eye's primary hits, for checking against the CPU
};
RayThroughput measureRayThroughput(const DeviceScene& scene, const StereoRig& rig, int repeats, cudaStream_t stream);

}  // namespace pvr::cuda
