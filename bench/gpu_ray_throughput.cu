#include <algorithm>
#include <vector>

#include "gpu_ray_throughput.h"
#include "pvr/cuda/device_scene.cuh"
#include "pvr/cuda/device_wide_bvh.h"
#include "pvr/cuda/eye_kernels.cuh"

namespace pvr {
using namespace cuda;
namespace {

// The traversal stack in shared memory (the renderer's choice) or in local memory (for comparison).
template <bool SharedStack, class Intersector>
__device__ inline Intersector stackFor(const Intersector& in) {
  if constexpr (SharedStack) return withSharedStack<kTile * kTile>(in);
  else return in;
}

// Ray-throughput kernels: one ray per pixel (centre), or one per primary hit.
template <class Intersector, bool SharedStack>
__global__ void primaryRaysKernel(Intersector sceneIntersector, EyeCamera camera, Hit* hits) {
  const Intersector intersector = stackFor<SharedStack>(sceneIntersector);
  int x, y;
  if (!tilePixel(camera.width, camera.height, x, y)) return;
  Hit hit;
  intersector.intersect(camera.generateRay(float(x) + 0.5f, float(y) + 0.5f), INFINITY, hit);
  hits[size_t(y) * camera.width + x] = hit;
}

__device__ inline bool primaryPoint(const SceneView& scene, const EyeCamera& camera, const Hit* hits, int x, int y,
                                    SurfacePoint& sp) {
  Hit hit = hits[size_t(y) * camera.width + x];
  if (!hit.valid()) return false;
  sp = scene.surfacePoint(hit);
  Ray ray = camera.generateRay(float(x) + 0.5f, float(y) + 0.5f);
  if (dot(ray.dir, sp.geometricNormal) > 0.0f) sp.geometricNormal = -sp.geometricNormal;
  return true;
}

template <class Intersector, bool SharedStack>
__global__ void shadowRaysKernel(SceneView scene, Intersector sceneIntersector, EyeCamera camera, const Hit* hits,
                                 uint8_t* occluded) {
  const Intersector intersector = stackFor<SharedStack>(sceneIntersector);
  int x, y;
  if (!tilePixel(camera.width, camera.height, x, y)) return;
  SurfacePoint sp;
  size_t pixel = size_t(y) * camera.width + x;
  if (!primaryPoint(scene, camera, hits, x, y, sp)) return;
  CounterRng rng(7, uint32_t(pixel), 0);
  float uPick = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
  LightSample ls = sampleLight(scene, uPick, u1, u2);
  Vec3 origin = sp.position + sp.geometricNormal * scene.rayEpsilon();
  Vec3 d = ls.position - origin;
  float dist = length(d);
  occluded[pixel] = intersector.occluded({origin, d / dist}, dist * (1.0f - 1e-3f)) ? 1 : 0;
}

template <class Intersector, bool SharedStack>
__global__ void diffuseRaysKernel(SceneView scene, Intersector sceneIntersector, EyeCamera camera, const Hit* hits,
                                  Hit* out) {
  const Intersector intersector = stackFor<SharedStack>(sceneIntersector);
  int x, y;
  if (!tilePixel(camera.width, camera.height, x, y)) return;
  SurfacePoint sp;
  size_t pixel = size_t(y) * camera.width + x;
  Hit hit;
  if (primaryPoint(scene, camera, hits, x, y, sp)) {
    CounterRng rng(11, uint32_t(pixel), 0);
    // Two statements: the order of evaluation of arguments differs between g++ and nvcc.
    float uTheta = rng.uniform();
    float uPhi = rng.uniform();
    Vec3 local = sampleCosineHemisphere(uTheta, uPhi);
    Ray ray{sp.position + sp.geometricNormal * scene.rayEpsilon(), Frame::fromNormal(sp.geometricNormal).toWorld(local)};
    intersector.intersect(ray, INFINITY, hit);
  }
  out[pixel] = hit;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}



template <class Intersector, bool SharedStack>
GpuRayThroughput measureRays(CudaFrameBackend& backend, const Intersector& sceneIntersector, const StereoRig& rig,
                             int repeats) {
  const DeviceScene& scene = backend.deviceScene();
  cudaStream_t stream = backend.stream();
  GpuRayThroughput out;
  const size_t pixels = size_t(rig.width) * rig.height;
  DeviceBuffer<Hit> primary[2], secondary;
  DeviceBuffer<uint8_t> occluded;
  for (auto& p : primary) p.reserve(pixels, "primary hits");
  secondary.reserve(pixels, "diffuse hits");
  occluded.reserve(pixels, "shadow results");
  std::vector<double> timesPrimary, timesShadow, timesDiffuse;
  EventTimer timer;
  dim3 grid = tileGrid(rig.width, rig.height), block(kTile, kTile);
  for (int r = -1; r < repeats; ++r) {  // r = -1 warms up
    double primaryMs = 0, shadowMs = 0, diffuseMs = 0;
    for (int e = 0; e < 2; ++e) {
      EyeCamera camera = rig.eye(Eye(e));
      timer.start(stream);
      launch("primary rays", primaryRaysKernel<Intersector, SharedStack>, grid, block, 0, stream, sceneIntersector, camera, primary[e].data());
      timer.stop(stream);
      primaryMs += timer.ms();
      timer.start(stream);
      launch("shadow rays", shadowRaysKernel<Intersector, SharedStack>, grid, block, 0, stream, scene.view, sceneIntersector, camera,
             primary[e].data(), occluded.data());
      timer.stop(stream);
      shadowMs += timer.ms();
      timer.start(stream);
      launch("diffuse rays", diffuseRaysKernel<Intersector, SharedStack>, grid, block, 0, stream, scene.view, sceneIntersector, camera,
             primary[e].data(), secondary.data());
      timer.stop(stream);
      diffuseMs += timer.ms();
    }
    if (r < 0) continue;
    timesPrimary.push_back(primaryMs);
    timesShadow.push_back(shadowMs);
    timesDiffuse.push_back(diffuseMs);
  }
  out.primaryMs = median(timesPrimary), out.shadowMs = median(timesShadow), out.diffuseMs = median(timesDiffuse);
  std::vector<Hit> hits(pixels);
  out.primaryRays = 2 * pixels;
  for (int e = 1; e >= 0; --e) {
    primary[e].download(hits.data(), pixels, stream);
    for (const Hit& h : hits) out.shadowRays += h.valid() ? 1 : 0;
  }
  out.diffuseRays = out.shadowRays;
  out.leftPrimaryHits = std::move(hits);  // the left eye's, downloaded last
  return out;
}

}  // namespace

struct GpuRayBench::Impl {
  CudaFrameBackend& backend;
  DeviceBuffer<BvhNode> binaryNodes;
  DeviceBuffer<BvhTriangle> triangles;
  BvhIntersector binary;
  DeviceWideBvh wide;
  explicit Impl(CudaFrameBackend& b) : backend(b) {}
};

GpuRayBench::GpuRayBench(CudaFrameBackend& backend, const Bvh& bvh) : impl_(std::make_unique<Impl>(backend)) {
  impl_->binaryNodes.upload(bvh.nodes().data(), bvh.nodes().size(), "BVH nodes");
  impl_->triangles.upload(bvh.triangles().data(), bvh.triangles().size(), "BVH triangles");
  impl_->binary.bvh = {impl_->binaryNodes.data(), impl_->triangles.data(), uint32_t(bvh.nodes().size()),
                       uint32_t(bvh.triangles().size())};
  impl_->binary.alphaScene = backend.deviceScene().intersector.alphaScene;
}

GpuRayBench::GpuRayBench(CudaFrameBackend& backend, const WideBvh& bvh) : impl_(std::make_unique<Impl>(backend)) {
  impl_->wide.upload(bvh, backend.deviceScene().intersector.alphaScene, nullptr);
}

GpuRayBench::~GpuRayBench() = default;

GpuRayThroughput GpuRayBench::measure(const StereoRig& rig, int repeats, bool sharedStack) {
  PVR_CUDA_CHECK(cudaDeviceSynchronize());
  Impl& m = *impl_;
  if (m.wide.uploaded)
    return sharedStack ? measureRays<WideBvhIntersector, true>(m.backend, m.wide.intersector, rig, repeats)
                       : measureRays<WideBvhIntersector, false>(m.backend, m.wide.intersector, rig, repeats);
  return sharedStack ? measureRays<BvhIntersector, true>(m.backend, m.binary, rig, repeats)
                     : measureRays<BvhIntersector, false>(m.backend, m.binary, rig, repeats);
}

std::vector<double> timePhotonTrace(CudaFrameBackend& backend, const PhotonTraceParams& params, int repeats,
                                    size_t& stored) {
  PVR_CUDA_CHECK(cudaDeviceSynchronize());
  cudaStream_t stream = backend.stream();
  EventTimer timer;
  std::vector<double> ms;
  for (int r = -1; r < repeats; ++r) {  // r = -1 warms up (and sizes the tracer's buffers)
    timer.start(stream);
    stored = backend.tracePhotons(params, 0, 1);
    timer.stop(stream);
    const double t = timer.ms();
    if (r >= 0) ms.push_back(t);
  }
  return ms;
}

}  // namespace pvr
