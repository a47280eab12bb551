#pragma once
// The eye pass on the GPU: the paper's single / hybrid / shared-memory schemes and our
// cell-sorted one at full resolution (eye_pass.cu), foveated passes through a mask's vertices
// (foveated_eye.cu), and stereo scatter (stereo_scatter.cu), over the shared gathering code.
// Density estimation kernels are in density.cuh.
#include "pvr/cuda/device_scene.cuh"
#include "pvr/foveation/reconstruct.h"
#include "pvr/photon/deferred_shadows.h"
#include "pvr/pipeline/frame_backend.h"

namespace pvr::cuda {

class GpuSurfaceCache;

// The photon map the eye pass reads: exactly one of grid and tree is set; the surface cache over
// it (DensityScheme::SurfaceCache, shared by both eyes' passes of the frame).
struct DeviceMap {
  const HashGridView* grid = nullptr;
  const KdTreeView* tree = nullptr;
  GpuSurfaceCache* surfaceCache = nullptr;
};

// Per-pixel outputs of an eye pass besides its image (null pointers are not written).
struct EyeOutputs {
  Vec3* image = nullptr;
  uint32_t* firstPrim = nullptr;
  float* inverseDepth = nullptr;
  SurfaceRecord* surfaces = nullptr;  ///< the left eye under stereo reuse
  uint32_t* reusedFrom = nullptr;     ///< the right eye under stereo reuse
  unsigned* reusedCount = nullptr;    ///< with reusedFrom: pixels that took the left eye's shading
  // The denoiser's guides (pvr::PixelGuide), all four or none.
  Vec3* emitted = nullptr;
  Vec3* direct = nullptr;
  Vec3* albedo = nullptr;
  Vec3* normal = nullptr;
};

// Gather points on the device: what every point has in four planes of 16-byte texels (a warp's
// 8x4 pixels then store and load whole 128-byte lines, where a 52-byte struct per point cost 8x
// the L2 traffic: ncu had the eye-ray kernel at 88 % of L2 bandwidth, 81 % of its sectors
// excess), and the BSDF of microfacet points, written and read only where present.
struct GatherPointCore {
  Vec3 radiance, weight, position, normal;
  uint32_t lobes;
};
struct GatherPointLobe {
  Vec3 wo;
  BsdfParams bsdf;
};
enum GatherPointPlane : int { kPlaneRadiance = 0, kPlaneWeight, kPlanePosition, kPlaneNormal, kGatherPointPlanes };
struct GatherPointStore {
  float4* planes[kGatherPointPlanes] = {};  ///< radiance (w: the lobes' bits), weight, position, normal
  GatherPointLobe* lobe = nullptr;
#ifdef __CUDACC__
  __device__ void store(size_t i, const GatherPoint& p) const {
    planes[kPlaneRadiance][i] = make_float4(p.radiance.x, p.radiance.y, p.radiance.z, __uint_as_float(p.lobes));
    planes[kPlaneWeight][i] = make_float4(p.weight.x, p.weight.y, p.weight.z, p.wall.x);
    planes[kPlanePosition][i] = make_float4(p.position.x, p.position.y, p.position.z, p.wall.y);
    planes[kPlaneNormal][i] = make_float4(p.normal.x, p.normal.y, p.normal.z, p.wall.z);
    if (p.lobes) lobe[i] = GatherPointLobe{p.wo, p.bsdf};
  }
  __device__ static Vec3 xyz(float4 v) { return {v.x, v.y, v.z}; }
  __device__ GatherPointCore coreAt(size_t i) const {
    const float4 r = planes[kPlaneRadiance][i];
    return {xyz(r), xyz(planes[kPlaneWeight][i]), xyz(planes[kPlanePosition][i]), xyz(planes[kPlaneNormal][i]),
            __float_as_uint(r.w)};
  }
  __device__ GatherPoint load(size_t i) const {
    const float4 r = planes[kPlaneRadiance][i], w = planes[kPlaneWeight][i], x = planes[kPlanePosition][i],
                 n = planes[kPlaneNormal][i];
    GatherPoint p;
    p.radiance = xyz(r), p.weight = xyz(w), p.position = xyz(x), p.normal = xyz(n), p.lobes = __float_as_uint(r.w);
    p.wall = {w.w, x.w, n.w};  // Boundary::Clipped's nearest wall
    if (p.lobes) {
      const GatherPointLobe l = lobe[i];
      p.wo = l.wo, p.bsdf = l.bsdf;
    }
    return p;
  }
  __device__ bool needsEstimate(size_t i) const { return !isBlack(xyz(planes[kPlaneWeight][i])); }
#endif
};
struct DeviceGatherPoints {
  DeviceBuffer<float4> planes[kGatherPointPlanes];
  DeviceBuffer<GatherPointLobe> lobe;
  void reserve(size_t n, const char* what) {
    for (DeviceBuffer<float4>& p : planes) p.reserve(n, what);
    lobe.reserve(n, what);
  }
  GatherPointStore view() {
    GatherPointStore s;
    for (int k = 0; k < kGatherPointPlanes; ++k) s.planes[k] = planes[k].data();
    s.lobe = lobe.data();
    return s;
  }
  size_t bytes() const {
    size_t b = lobe.bytes();
    for (const DeviceBuffer<float4>& p : planes) b += p.bytes();
    return b;
  }
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

class GpuEyePass {
 public:
  // Shades one eye at full resolution into image(eye), firstPrim(eye) and inverseDepth(eye),
  // timing its eye rays and density estimation on `clock`. Under stereo reuse the source (left)
  // eye records its surfaces and the reuser (right), rendered after it (and after scatter() for
  // Scatter), takes the left eye's shading where it may.
  void render(const DeviceScene& scene, DeviceMap map, const EyePass& pass, cudaStream_t stream, StageClock& clock);
  // Foveated: lists the mask's vertices in use for the eye's gaze, shades them (eye rays, then
  // estimates) and rasterizes the eye's image, depth and sample spacing from them; firstPrim(eye)
  // is not written.
  void renderFoveated(const DeviceScene& scene, DeviceMap map, const EyePass& pass, const DeviceMaskView& mask,
                      cudaStream_t stream, StageClock& clock);
  // The number of vertices the last foveated pass of each eye shaded, copied when the stream gets there.
  void downloadShadedVertices(uint32_t host[2], cudaStream_t stream) const;
  // Scatter: projects the left eye's recorded surfaces into the target (right) image.
  void scatter(const DeviceScene& scene, const EyeCamera& target, cudaStream_t stream);
  const Vec3* image(Eye e) const { return images_[int(e)].data(); }
  const uint32_t* firstPrim(Eye e) const { return firstPrim_[int(e)].data(); }
  const float* inverseDepth(Eye e) const { return inverseDepth_[int(e)].data(); }
  const float* sampleSpacing(Eye e) const { return sampleSpacing_[int(e)].data(); }  ///< foveated only
  const uint32_t* reusedFrom() const { return reusedFrom_.data(); }
  // The denoiser's guides of the last full-resolution pass of an eye that wrote them.
  const Vec3* emitted(Eye e) const { return emitted_[int(e)].data(); }
  const Vec3* direct(Eye e) const { return direct_[int(e)].data(); }
  const Vec3* albedo(Eye e) const { return albedo_[int(e)].data(); }
  const Vec3* normal(Eye e) const { return normal_[int(e)].data(); }
  // The gather points of the last full-resolution pass's last sample (the right eye's, under stereo).
  const DeviceGatherPoints& gatherPoints() const { return points_; }
  // The right eye's reused-sample count, copied to the host when the stream reaches it.
  void downloadReusedCount(unsigned* host, cudaStream_t stream) const;
  size_t memoryBytes() const;

 private:
  // Sets up the pass's part in stereo reuse: the left eye's surface records in `out`, or the
  // right eye's view of them, with its reuse outputs in `out`.
  StereoReuseView prepareReuse(const EyePass& pass, cudaStream_t stream, EyeOutputs& out);

  DeviceBuffer<Vec3> images_[2];
  DeviceBuffer<uint32_t> firstPrim_[2];
  DeviceBuffer<float> inverseDepth_[2], sampleSpacing_[2];
  DeviceBuffer<Vec3> emitted_[2], direct_[2], albedo_[2], normal_[2];
  DeviceBuffer<SurfaceRecord> surfaces_;
  DeviceBuffer<uint64_t> scattered_;
  DeviceBuffer<uint32_t> reusedFrom_;
  DeviceBuffer<unsigned> reusedCount_;
  DeviceBuffer<uint32_t> shadeList_;                     ///< gather's right eye: the pixels it does not reuse
  DeviceBuffer<unsigned> shadeCount_;
  DeviceBuffer<uint32_t> estimateList_, estimateCount_;  ///< the right eye's points still to estimate
  DeviceBuffer<uint8_t> vertexUsed_;
  DeviceBuffer<uint32_t> vertexList_, vertexCount_;  ///< foveated: the vertices shaded (count per eye)
  DeviceGatherPoints vertexPoints_;
  DeviceBuffer<Vec3> vertexColours_;
  DeviceBuffer<float> vertexInverseDepths_;
  DeviceGatherPoints points_;
  DeviceBuffer<Hit> firstHits_;  ///< sample 0's, from the first-hit pre-pass
  DeviceBuffer<ShadowQuery> shadowQueries_;                ///< deferred shadows' (DeferredShadowsView)
  DeviceBuffer<uint8_t> shadowsAsked_, shadowsBlocked_;
  DeviceBuffer<uint32_t> sortKeys_[2], sortValues_[2];
  DeviceBuffer<unsigned char> temp_;
};

}  // namespace pvr::cuda
