#include <cub/device/device_select.cuh>
#include <thrust/iterator/counting_iterator.h>

#include "pvr/cuda/density.cuh"
#include "pvr/cuda/eye_kernels.cuh"

namespace pvr::cuda {
namespace {

// Foveated rendering: the mask's vertices in use for a gaze (any triangle overlapping the image).
// Every pixel's sample spacing at 1 before the raster writes the covered ones (as on the CPU). A
// kernel rather than thrust::fill_n, whose policy waits for the stream and reports a failure of
// earlier work as its own.
__global__ void fillSpacingKernel(float* spacing, size_t pixels) {
  const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < pixels) spacing[i] = 1.0f;
}

__global__ void markUsedVerticesKernel(DeviceMaskView mask, int gazeX, int gazeY, int width, int height, uint8_t* used) {
  uint32_t t = blockIdx.x * blockDim.x + threadIdx.x;
  if (t >= mask.triangleCount) return;
  MaskPoint v[3];
  uint32_t index[3];
  placeTriangle(mask.offsets, mask.triangles, t, gazeX, gazeY, v, index);
  int x0, x1, y0, y1;
  if (triangleBounds(v, width, height, x0, x1, y0, y1))
    for (uint32_t i : index) used[i] = 1;  // every writer writes 1
}

struct VertexInUse {
  const uint8_t* used;
  __device__ bool operator()(uint32_t vertex) const { return used[vertex] != 0; }
};

// Eye rays through the listed vertices, to their gather points (indexed by vertex).
// Foveated: the listed vertices' eye rays. Under stereo reuse, those on pixel centres take the
// pixel path: the left eye (Source) records their surfaces, the right (Reuser) may reuse them and
// counts those it did. Separate rendering keeps the leaner per-position path (same result).
constexpr int kVertexBlock = 128;

template <StereoRole R>
__global__ void vertexRaysKernel(SceneView scene, SceneIntersector sceneIntersector, GatherParams params, EyeCamera camera,
                                 Eye eye, DeviceMaskView mask, int gazeX, int gazeY, const uint32_t* list,
                                 const uint32_t* listed, StereoReuseView reuse, EyeOutputs out, GatherPointStore points,
                                 float* inverseDepths) {
  const SceneIntersector intersector = withSharedStack<kVertexBlock>(sceneIntersector);
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  const bool shaded = i < *listed;
  const uint32_t vertex = shaded ? list[i] : 0u;
  GatherPoint point;
  PixelSample sample;  // the first hit's inverse depth; and the reuse decision
  if (shaded) {
    const MaskPoint o = mask.offsets[vertex];
    const float px = o.x + float(gazeX) + 0.5f, py = o.y + float(gazeY) + 0.5f;
    if constexpr (R == StereoRole::Alone)
      point = imagePositionGatherPoint(scene, intersector, params, camera, eye, px, py, sample.inverseDepth);
    else
      point = vertexGatherPoint(scene, intersector, params, camera, eye, px, py, reuseFor<R>(reuse), sample,
                                R == StereoRole::Source ? out.surfaces : nullptr);
  }
  finishShadingTogether();
  if (!shaded) return;
  points.store(vertex, point);
  inverseDepths[vertex] = sample.inverseDepth;
  if constexpr (R == StereoRole::Reuser) countInWarp(out.reusedCount, sample.reusedFrom != kNotReused);
}

// `Lanes` threads per listed triangle, splitting its bounding box: the periphery's triangles
// cover hundreds of pixels (a warp each, or the GPU waits on the largest), the fovea's one or two
// (a thread each, or 30 of 32 lanes idle).
template <int Lanes>
__global__ void rasterKernel(DeviceMaskView mask, const uint32_t* list, uint32_t count, int gazeX, int gazeY,
                             VertexValues vertices, RasterTarget target) {
  uint32_t i = (blockIdx.x * blockDim.x + threadIdx.x) / Lanes;
  if (i < count)
    rasterizeTriangle(mask.offsets, mask.triangles, list[i], gazeX, gazeY, vertices, target,
                      int(threadIdx.x % Lanes), Lanes);
}


}  // namespace

void GpuEyePass::downloadShadedVertices(uint32_t host[2], cudaStream_t stream) const {
  PVR_CUDA_CHECK(cudaMemcpyAsync(host, vertexCount_.data(), 2 * sizeof(uint32_t), cudaMemcpyDeviceToHost, stream));
}

void GpuEyePass::renderFoveated(const DeviceScene& scene, DeviceMap map, const EyePass& pass,
                                const DeviceMaskView& mask, cudaStream_t stream, StageClock& clock) {
  const Eye eye = pass.eye;
  const int e = int(eye);
  const EyeCamera& camera = pass.camera;
  const size_t pixels = size_t(camera.width) * camera.height;
  const GatherParams& params = pass.gather;
  const bool knn = params.density.estimator == Estimator::Knn;
  const int gazeX = pass.gazeX, gazeY = pass.gazeY;
  images_[e].reserve(pixels, "eye image");
  inverseDepth_[e].reserve(pixels, "eye depths");
  sampleSpacing_[e].reserve(pixels, "eye sample spacing");
  vertexUsed_.reserve(mask.vertexCount, "mask vertices in use");
  vertexList_.reserve(mask.vertexCount, "mask vertices to shade");
  vertexCount_.reserve(2, "mask vertices shaded");
  vertexPoints_.reserve(mask.vertexCount, "mask vertex gather points");
  vertexColours_.reserve(mask.vertexCount, "mask vertex colours");
  vertexInverseDepths_.reserve(mask.vertexCount, "mask vertex depths");
  uint32_t* count = vertexCount_.data() + e;
  EyeOutputs out;
  const StereoReuseView reuse = prepareReuse(pass, stream, out);
  size_t bytes = 0;
  thrust::counting_iterator<uint32_t> vertices(0);
  PVR_CUDA_CHECK(cub::DeviceSelect::If(nullptr, bytes, vertices, vertexList_.data(), count, int(mask.vertexCount),
                                       VertexInUse{vertexUsed_.data()}, stream));
  temp_.reserve(bytes, "mask vertex selection scratch");

  {
    StageScope scope(clock, Stage::EyeRays, e);
    PVR_CUDA_CHECK(cudaMemsetAsync(vertexUsed_.data(), 0, mask.vertexCount, stream));
    launch("mask vertices in use", markUsedVerticesKernel, blocksFor(mask.triangleCount, 256), 256, 0, stream, mask,
           gazeX, gazeY, camera.width, camera.height, vertexUsed_.data());
    bytes = temp_.capacity();
    PVR_CUDA_CHECK(cub::DeviceSelect::If(temp_.data(), bytes, vertices, vertexList_.data(), count, int(mask.vertexCount),
                                         VertexInUse{vertexUsed_.data()}, stream));
    auto* vertexRays = pass.role == StereoRole::Reuser   ? vertexRaysKernel<StereoRole::Reuser>
                       : pass.role == StereoRole::Source ? vertexRaysKernel<StereoRole::Source>
                                                         : vertexRaysKernel<StereoRole::Alone>;
    launch("eye rays (mask vertices)", vertexRays, blocksFor(mask.vertexCount, kVertexBlock), kVertexBlock, 0, stream, scene.view,
           scene.intersector, params, camera, eye, mask, gazeX, gazeY, vertexList_.data(), count, reuse, out,
           vertexPoints_.view(), vertexInverseDepths_.data());
  }
  {
    StageScope scope(clock, Stage::Density, e);
    // One warp per vertex, also for Geisler-Perry's ~300k: one thread per vertex was measured
    // slower there on the H100 (6.0 against 4.5 ms for both eyes' pass).
    if (map.grid && !knn)
      estimateWarpPerPoint(*map.grid, params.density.radius, vertexPoints_.view(), vertexList_.data(), count, 0, 1,
                           vertexColours_.data(), stream);
    else
      estimateListed(map, params.density, vertexPoints_.view(), vertexList_.data(), count, mask.vertexCount,
                     vertexColours_.data(), stream);
  }

  StageScope scope(clock, Stage::Reconstruct, e);
  // A gaze inside the image leaves no pixel uncovered; these are for the rest.
  PVR_CUDA_CHECK(cudaMemsetAsync(images_[e].data(), 0, pixels * sizeof(Vec3), stream));
  PVR_CUDA_CHECK(cudaMemsetAsync(inverseDepth_[e].data(), 0, pixels * sizeof(float), stream));
  if (pixels)
    launch("sample spacing fill", fillSpacingKernel, blocksFor(pixels, 256), 256, 0, stream, sampleSpacing_[e].data(),
           size_t(pixels));
  const VertexValues values{vertexColours_.data(), vertexInverseDepths_.data()};
  const RasterTarget target{images_[e].data(), inverseDepth_[e].data(), sampleSpacing_[e].data(), camera.width,
                            camera.height};
  if (mask.smallCount)
    launch("foveated raster (small triangles)", rasterKernel<1>, blocksFor(mask.smallCount, 256), 256, 0, stream, mask,
           mask.smallTriangles, mask.smallCount, gazeX, gazeY, values, target);
  if (mask.largeCount)
    launch("foveated raster (large triangles)", rasterKernel<32>, blocksFor(size_t(mask.largeCount) * 32, 256), 256, 0,
           stream, mask, mask.largeTriangles, mask.largeCount, gazeX, gazeY, values, target);
}

}  // namespace pvr::cuda
