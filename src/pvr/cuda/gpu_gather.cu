#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_select.cuh>
#include <thrust/execution_policy.h>
#include <thrust/fill.h>
#include <thrust/iterator/counting_iterator.h>

#include <algorithm>
#include <vector>

#include "pvr/cuda/gpu_gather.cuh"

namespace pvr::cuda {
namespace {

constexpr int kTile = 8;  // 8x8-pixel blocks: each warp an 8x4 tile of coherent rays and hit points

__device__ inline bool tilePixel(int width, int height, int& x, int& y) {
  x = int(blockIdx.x) * kTile + int(threadIdx.x);
  y = int(blockIdx.y) * kTile + int(threadIdx.y);
  return x < width && y < height;
}

dim3 tileGrid(int width, int height) { return dim3(unsigned((width + kTile - 1) / kTile), unsigned((height + kTile - 1) / kTile)); }

// Stores the sample's contribution: the running sum, scaled on the last sample (the CPU's order).
__device__ inline void storeSample(Vec3* image, size_t pixel, Vec3 c, int sample, int samples) {
  Vec3 v = sample == 0 ? c : image[pixel] + c;
  if (sample == samples - 1 && samples > 1) v *= 1.0f / float(samples);
  image[pixel] = v;
}

// Everything of a pixel but its radiance and surface: first-hit id and the reuse decision (counted
// per warp: one atomic per warp, not per pixel).
__device__ inline void recordPixel(const EyeOutputs& out, size_t pixel, const PixelSample& p) {
  out.firstPrim[pixel] = p.firstPrim;
  out.inverseDepth[pixel] = p.inverseDepth;
  if (!out.reusedFrom) return;
  out.reusedFrom[pixel] = p.reusedFrom;
  countInWarp(out.reusedCount, p.reusedFrom != kNotReused);
}

// An eye's part in stereo reuse, a compile-time kernel parameter: the reuse code paths cost
// registers, so an eye that does not reuse gets kernels without them.
enum class StereoRole : int {
  Alone = 0,   ///< separate rendering
  Source = 1,  ///< the left eye under reuse: records its surfaces
  Reuser = 2,  ///< the right eye under reuse
};

template <StereoRole R>
__device__ inline StereoReuseView reuseFor(const StereoReuseView& reuse) {
  if constexpr (R == StereoRole::Reuser) return reuse;
  else return StereoReuseView();
}

template <StereoRole R>
__device__ inline SurfaceRecord* surfaceFor(const EyeOutputs& out, size_t pixel) {
  if constexpr (R == StereoRole::Source) return out.surfaces + pixel;
  else return nullptr;
}

// The paper's "single" scheme: eye ray and estimate in one kernel.
template <class Map, Estimator E, StereoRole R>
__global__ void singleKernel(SceneView scene, BvhIntersector intersector, Map map, GatherParams params,
                             EyeCamera camera, Eye eye, StereoReuseView reuse, EyeOutputs out) {
  int x, y;
  if (!tilePixel(camera.width, camera.height, x, y)) return;
  params.density.estimator = E;  // compile-time estimator: the radius kernel carries no heap
  size_t pixel = size_t(y) * camera.width + x;
  PixelSample s = shadePixel(scene, intersector, map, params, camera, eye, x, y, reuseFor<R>(reuse),
                             surfaceFor<R>(out, pixel));
  out.image[pixel] = s.radiance;
  recordPixel(out, pixel, s);
}

// Hybrid, first kernel: eye rays to their gather points (a reused pixel's carries its colour).
template <StereoRole R>
__global__ void eyeRaysKernel(SceneView scene, BvhIntersector intersector, GatherParams params, EyeCamera camera,
                              Eye eye, int sample, StereoReuseView reuse, GatherPoint* points, EyeOutputs out) {
  int x, y;
  if (!tilePixel(camera.width, camera.height, x, y)) return;
  size_t pixel = size_t(y) * camera.width + x;
  PixelSample state;
  if (R == StereoRole::Reuser && sample > 0) state.reusedFrom = out.reusedFrom[pixel];  // sample 0 decided
  points[pixel] = pixelGatherPoint(scene, intersector, params, camera, eye, x, y, sample, reuseFor<R>(reuse), state,
                                   surfaceFor<R>(out, pixel));
  if (sample == 0) recordPixel(out, pixel, state);
}

// Scatter: each left pixel's reusable surface, if the right eye sees it, lands on one right pixel;
// the nearest one per pixel wins.
__global__ void scatterKernel(SceneView scene, BvhIntersector intersector, const SurfaceRecord* surfaces,
                              int sourceWidth, int sourceHeight, EyeCamera target, unsigned long long* scattered) {
  int x, y;
  if (!tilePixel(sourceWidth, sourceHeight, x, y)) return;
  uint32_t source = uint32_t(y) * uint32_t(sourceWidth) + uint32_t(x);
  uint32_t pixel;
  uint64_t entry;
  if (scatterTarget(scene, intersector, surfaces[source], source, target, pixel, entry))
    atomicMin(scattered + pixel, static_cast<unsigned long long>(entry));
}

// Hybrid, second kernel: one estimate per gather point, in the same 8x8 tiles.
template <class Map, Estimator E>
__global__ void densityKernel(Map map, DensityParams density, const GatherPoint* points, int width, int height,
                              int sample, int samples, Vec3* image) {
  int x, y;
  if (!tilePixel(width, height, x, y)) return;
  density.estimator = E;
  size_t pixel = size_t(y) * width + x;
  storeSample(image, pixel, finishGather(map, points[pixel], density), sample, samples);
}

// The paper's Algorithm 1. The threads of an 8x8 block find their gather points' cells; if all
// that need an estimate agree on one cell, the block walks that cell's 9 neighbouring rows
// together, each thread staging one photon of every 64 into shared memory, and each thread
// tests all staged photons against its own point. Otherwise each thread estimates alone.
template <Estimator E>
__global__ void __launch_bounds__(kTile* kTile) sharedDensityKernel(HashGridView map, DensityParams density,
                                                                    const GatherPoint* points, int width, int height,
                                                                    int sample, int samples, Vec3* image) {
  constexpr int kThreads = kTile * kTile;
  __shared__ Photon staged[kThreads];
  __shared__ int cellMin, cellMax;
  int tid = int(threadIdx.y) * kTile + int(threadIdx.x);
  int x, y;
  bool inside = tilePixel(width, height, x, y);
  size_t pixel = size_t(y) * width + x;
  GatherPoint gp;
  if (inside) gp = points[pixel];
  int64_t cell = inside && gp.needsEstimate() ? map.cellOf(gp.position) : -1;
  bool estimating = cell >= 0;  // a point outside the grid has no photons in reach
  if (tid == 0) cellMin = INT_MAX, cellMax = -1;
  __syncthreads();
  if (estimating) {
    atomicMin(&cellMin, int(cell));
    atomicMax(&cellMax, int(cell));
  }
  __syncthreads();
  density.estimator = E;
  Vec3 result = gp.radiance;
  if (cellMin != cellMax) {  // the block disagrees (block-uniform branch)
    if (estimating) result = finishGather(map, gp, density);
  } else if (cellMax >= 0) {
    float r2 = density.radius * density.radius;
    Vec3 sum{0, 0, 0};
    KnnHeap heap(E == Estimator::Knn ? density.k : 1);
    float searchR2 = r2;
    for (int row = 0; row < 9; ++row) {
      uint32_t first = uint32_t(cellMax + map.rowOffsets[row]);
      uint32_t begin = map.cellStart[first], end = map.cellStart[first + 3];
      for (uint32_t base = begin; base < end; base += kThreads) {
        if (base + tid < end) staged[tid] = map.photons[base + tid];
        __syncthreads();
        uint32_t n = end - base < uint32_t(kThreads) ? end - base : uint32_t(kThreads);
        if (estimating) {
          for (uint32_t k = 0; k < n; ++k) {
            float d2 = photonDistance2(gp.position, staged[k].position);
            if (d2 <= searchR2 && photonFacesSurface(staged[k].direction, gp.normal)) {
              if (E == Estimator::Radius) sum += staged[k].power;
              else heap.offer(d2, base + k, searchR2);
            }
          }
        }
        __syncthreads();
      }
    }
    if (estimating) {
      Vec3 flux = E == Estimator::Radius ? sum * (1.0f / (kPi * r2)) : knnFluxDensity(map, heap, r2);
      result = gp.radiance + gp.weight * flux;
    }
  }
  if (inside) storeSample(image, pixel, result, sample, samples);
}

// Our improvement: gather points sorted by cell, so consecutive threads share their cell.
__global__ void cellKeysOfPointsKernel(HashGridView map, const GatherPoint* points, uint32_t n, uint32_t noCell,
                                       uint32_t* keys, uint32_t* values) {
  uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  GatherPoint gp = points[i];
  int64_t cell = gp.needsEstimate() ? map.cellOf(gp.position) : -1;
  keys[i] = cell < 0 ? noCell : uint32_t(cell);
  values[i] = i;
}

template <Estimator E>
__global__ void sortedDensityKernel(HashGridView map, DensityParams density, const GatherPoint* points,
                                    const uint32_t* order, uint32_t n, int sample, int samples, Vec3* image) {
  uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  density.estimator = E;
  uint32_t pixel = order[i];
  storeSample(image, pixel, finishGather(map, points[pixel], density), sample, samples);
}

// Under stereo reuse the right eye is left with a sparse set of gather points (disocclusions,
// edges, whatever is seen through mirrors and glass). One thread per point would leave the GPU
// waiting on a few long chains of dependent loads; instead the points are listed (CUB select) and
// each warp estimates one point, its lanes splitting every cell row's photons (radius estimate).
struct NeedsEstimate {
  const GatherPoint* points;
  __device__ bool operator()(uint32_t pixel) const { return points[pixel].needsEstimate(); }
};

__global__ void storeWithoutEstimateKernel(const GatherPoint* points, uint32_t n, int sample, int samples, Vec3* image) {
  uint32_t pixel = blockIdx.x * blockDim.x + threadIdx.x;
  if (pixel >= n) return;
  GatherPoint gp = points[pixel];
  if (!gp.needsEstimate()) storeSample(image, pixel, gp.radiance, sample, samples);
}

__global__ void warpPerPointDensityKernel(HashGridView map, float radius, const GatherPoint* points,
                                          const uint32_t* list, const uint32_t* listed, int sample, int samples,
                                          Vec3* image) {
  const unsigned lane = threadIdx.x & 31u;
  const uint32_t warps = (gridDim.x * blockDim.x) >> 5;
  const float r2 = radius * radius;
  const uint32_t n = *listed;
  for (uint32_t i = (blockIdx.x * blockDim.x + threadIdx.x) >> 5; i < n; i += warps) {  // warp-uniform
    uint32_t pixel = list[i];
    GatherPoint gp = points[pixel];
    Vec3 sum{0, 0, 0};
    // No estimate for a point without a diffuse surface, or one reused from the other eye.
    int64_t cell = map.photonCount && gp.needsEstimate() ? map.cellOf(gp.position) : -1;
    for (int row = 0; cell >= 0 && row < 9; ++row) {
      uint32_t first = uint32_t(cell + map.rowOffsets[row]);
      uint32_t end = map.cellStart[first + 3];
      for (uint32_t j = map.cellStart[first] + lane; j < end; j += 32) {
        if (photonDistance2(gp.position, map.position(j)) <= r2 && photonFacesSurface(map.photons[j].direction, gp.normal))
          sum += map.photons[j].power;
      }
    }
    for (int offset = 16; offset > 0; offset >>= 1) {
      sum.x += __shfl_xor_sync(0xffffffffu, sum.x, offset);
      sum.y += __shfl_xor_sync(0xffffffffu, sum.y, offset);
      sum.z += __shfl_xor_sync(0xffffffffu, sum.z, offset);
    }
    if (lane == 0) storeSample(image, pixel, gp.radiance + gp.weight * (sum * (1.0f / (kPi * r2))), sample, samples);
  }
}

// Foveated rendering: the mask's vertices in use for a gaze (any triangle overlapping the image).
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
template <StereoRole R>
__global__ void vertexRaysKernel(SceneView scene, BvhIntersector intersector, GatherParams params, EyeCamera camera,
                                 Eye eye, DeviceMaskView mask, int gazeX, int gazeY, const uint32_t* list,
                                 const uint32_t* listed, StereoReuseView reuse, EyeOutputs out, GatherPoint* points,
                                 float* inverseDepths) {
  uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= *listed) return;
  uint32_t vertex = list[i];
  MaskPoint o = mask.offsets[vertex];
  const float px = o.x + float(gazeX) + 0.5f, py = o.y + float(gazeY) + 0.5f;
  if constexpr (R == StereoRole::Alone) {
    float inverseDepth;  // a local: storing to global memory mid-path costs registers
    points[vertex] = imagePositionGatherPoint(scene, intersector, params, camera, eye, px, py, inverseDepth);
    inverseDepths[vertex] = inverseDepth;
  } else {
    PixelSample sample;
    points[vertex] = vertexGatherPoint(scene, intersector, params, camera, eye, px, py, reuseFor<R>(reuse), sample,
                                       R == StereoRole::Source ? out.surfaces : nullptr);
    inverseDepths[vertex] = sample.inverseDepth;
    if constexpr (R == StereoRole::Reuser) countInWarp(out.reusedCount, sample.reusedFrom != kNotReused);
  }
}

// One thread per listed gather point (kNN, or the kd-tree).
template <class Map, Estimator E>
__global__ void listedDensityKernel(Map map, DensityParams density, const GatherPoint* points, const uint32_t* list,
                                    const uint32_t* listed, Vec3* colours) {
  uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= *listed) return;
  density.estimator = E;
  uint32_t vertex = list[i];
  colours[vertex] = finishGather(map, points[vertex], density);
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

// Ray-throughput kernels: one ray per pixel (centre), or one per primary hit.
__global__ void primaryRaysKernel(BvhIntersector intersector, EyeCamera camera, Hit* hits) {
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

__global__ void shadowRaysKernel(SceneView scene, BvhIntersector intersector, EyeCamera camera, const Hit* hits,
                                 uint8_t* occluded) {
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

__global__ void diffuseRaysKernel(SceneView scene, BvhIntersector intersector, EyeCamera camera, const Hit* hits,
                                  Hit* out) {
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

template <Estimator E, class Map>
void launchSingle(const DeviceScene& scene, const Map& map, const GatherParams& params, const EyeCamera& camera,
                  Eye eye, const StereoReuseView& reuse, const EyeOutputs& out, cudaStream_t stream) {
  auto* kernel = out.reusedFrom ? singleKernel<Map, E, StereoRole::Reuser>
                 : out.surfaces ? singleKernel<Map, E, StereoRole::Source>
                                : singleKernel<Map, E, StereoRole::Alone>;
  kernel<<<tileGrid(camera.width, camera.height), dim3(kTile, kTile), 0, stream>>>(scene.view, scene.intersector, map,
                                                                                   params, camera, eye, reuse, out);
  PVR_CUDA_CHECK_LAUNCH("single");
}

template <Estimator E, class Map>
void launchDensity(const Map& map, const DensityParams& density, const GatherPoint* points, const EyeCamera& camera,
                   int sample, int samples, Vec3* image, cudaStream_t stream) {
  densityKernel<Map, E><<<tileGrid(camera.width, camera.height), dim3(kTile, kTile), 0, stream>>>(
      map, density, points, camera.width, camera.height, sample, samples, image);
  PVR_CUDA_CHECK_LAUNCH("density");
}

template <Estimator E>
void dispatchSingle(const DeviceScene& scene, DeviceMap map, const GatherParams& params, const EyeCamera& camera,
                    Eye eye, const StereoReuseView& reuse, const EyeOutputs& out, cudaStream_t stream) {
  if (map.grid) launchSingle<E>(scene, *map.grid, params, camera, eye, reuse, out, stream);
  else launchSingle<E>(scene, *map.tree, params, camera, eye, reuse, out, stream);
}

}  // namespace

StereoReuseView GpuGather::prepareReuse(const RenderOptions& options, const StereoRig& rig, Eye eye,
                                        cudaStream_t stream, EyeOutputs& out) {
  StereoReuseView reuse;
  if (options.stereo == StereoMode::Separate) return reuse;
  const size_t pixels = size_t(rig.width) * rig.height;
  if (eye == Eye::Left) {
    surfaces_.reserve(pixels, "left-eye surfaces");
    // Foveated, only the vertices' pixels are recorded: the rest must read as not reusable.
    if (options.foveation.mask)
      PVR_CUDA_CHECK(cudaMemsetAsync(surfaces_.data(), 0xff, pixels * sizeof(SurfaceRecord), stream));
    out.surfaces = surfaces_.data();
    return reuse;
  }
  reuse.mode = options.stereo;
  reuse.source = rig.eye(Eye::Left);
  reuse.sourceSurfaces = surfaces_.data();
  reuse.sourceImage = images_[int(Eye::Left)].data();
  reuse.scattered = options.stereo == StereoMode::Scatter ? scattered_.data() : nullptr;
  reusedCount_.reserve(1, "reuse count");
  PVR_CUDA_CHECK(cudaMemsetAsync(reusedCount_.data(), 0, sizeof(unsigned), stream));
  out.reusedCount = reusedCount_.data();
  if (!options.foveation.mask) {  // foveated reuse is per vertex: no per-pixel sources
    reusedFrom_.reserve(pixels, "reuse sources");
    out.reusedFrom = reusedFrom_.data();
  }
  return reuse;
}

size_t GpuGather::memoryBytes() const {
  size_t bytes = points_.bytes() + temp_.bytes() + surfaces_.bytes() + scattered_.bytes() + reusedFrom_.bytes() +
                 reusedCount_.bytes() + estimateList_.bytes() + estimateCount_.bytes() + vertexUsed_.bytes() +
                 vertexList_.bytes() + vertexCount_.bytes() + vertexPoints_.bytes() + vertexColours_.bytes() +
                 vertexInverseDepths_.bytes();
  for (int i = 0; i < 2; ++i)
    bytes += images_[i].bytes() + firstPrim_[i].bytes() + inverseDepth_[i].bytes() + sampleSpacing_[i].bytes() +
             sortKeys_[i].bytes() + sortValues_[i].bytes();
  return bytes;
}

void GpuGather::scatter(const DeviceScene& scene, const StereoRig& rig, cudaStream_t stream) {
  const size_t pixels = size_t(rig.width) * rig.height;
  scattered_.reserve(pixels, "scatter buffer");
  PVR_CUDA_CHECK(cudaMemsetAsync(scattered_.data(), 0xff, pixels * sizeof(uint64_t), stream));  // kNothingScattered
  scatterKernel<<<tileGrid(rig.width, rig.height), dim3(kTile, kTile), 0, stream>>>(
      scene.view, scene.intersector, surfaces_.data(), rig.width, rig.height, rig.eye(Eye::Right),
      reinterpret_cast<unsigned long long*>(scattered_.data()));
  PVR_CUDA_CHECK_LAUNCH("scatter");
}

void GpuGather::downloadReusedCount(unsigned* host, cudaStream_t stream) const {
  PVR_CUDA_CHECK(cudaMemcpyAsync(host, reusedCount_.data(), sizeof(unsigned), cudaMemcpyDeviceToHost, stream));
}

void GpuGather::renderEye(const DeviceScene& scene, DeviceMap map, const RenderOptions& options, const StereoRig& rig,
                          Eye eye, cudaStream_t stream, EyeTimers& timers) {
  const EyeCamera camera = rig.eye(eye);
  const size_t pixels = size_t(camera.width) * camera.height;
  const GatherParams& params = options.gather;
  const bool knn = params.density.estimator == Estimator::Knn;
  Vec3* image = (images_[int(eye)].reserve(pixels, "eye image"), images_[int(eye)].data());
  EyeOutputs out;
  out.image = image;
  out.firstPrim = (firstPrim_[int(eye)].reserve(pixels, "first-hit ids"), firstPrim_[int(eye)].data());
  out.inverseDepth = (inverseDepth_[int(eye)].reserve(pixels, "eye depths"), inverseDepth_[int(eye)].data());
  StereoReuseView reuse = prepareReuse(options, rig, eye, stream, out);

  if (options.kernel == DensityKernel::Single) {  // shadePixel loops over the samples itself
    timers.prepare(1);
    timers.rays[0]->start(stream);
    if (knn) dispatchSingle<Estimator::Knn>(scene, map, params, camera, eye, reuse, out, stream);
    else dispatchSingle<Estimator::Radius>(scene, map, params, camera, eye, reuse, out, stream);
    timers.rays[0]->stop(stream);
    timers.density[0]->start(stream);
    timers.density[0]->stop(stream);
    return;
  }

  points_.reserve(pixels, "gather points");
  const bool sparse = reuse.reusing() && map.grid && !knn;  // the right eye under stereo reuse
  const bool sorted = options.kernel == DensityKernel::CellSorted && !sparse;
  uint32_t noCell = 0;
  int endBit = 1;
  if (sorted) {
    for (int b = 0; b < 2; ++b) {
      sortKeys_[b].reserve(pixels, "gather-point cell keys");
      sortValues_[b].reserve(pixels, "gather-point order");
    }
    noCell = uint32_t(uint64_t(map.grid->dims[0]) * map.grid->dims[1] * map.grid->dims[2]);
    endBit = radixBitsFor(uint64_t(noCell) + 1);
    size_t bytes = 0;
    cub::DoubleBuffer<uint32_t> k(sortKeys_[0].data(), sortKeys_[1].data()), v(sortValues_[0].data(), sortValues_[1].data());
    PVR_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, bytes, k, v, int(pixels), 0, endBit, stream));
    temp_.reserve(bytes, "gather-point sort scratch");
  }
  if (sparse) {
    estimateList_.reserve(pixels, "gather points to estimate");
    estimateCount_.reserve(1, "gather points to estimate");
    size_t bytes = 0;
    PVR_CUDA_CHECK(cub::DeviceSelect::If(nullptr, bytes, thrust::counting_iterator<uint32_t>(0), estimateList_.data(),
                                         estimateCount_.data(), int(pixels), NeedsEstimate{points_.data()}, stream));
    temp_.reserve(bytes, "gather-point selection scratch");
  }
  timers.prepare(params.samplesPerPixel);
  for (int s = 0; s < params.samplesPerPixel; ++s) {
    timers.rays[s]->start(stream);
    auto* eyeRays = out.reusedFrom ? eyeRaysKernel<StereoRole::Reuser>
                    : out.surfaces ? eyeRaysKernel<StereoRole::Source>
                                   : eyeRaysKernel<StereoRole::Alone>;
    eyeRays<<<tileGrid(camera.width, camera.height), dim3(kTile, kTile), 0, stream>>>(
        scene.view, scene.intersector, params, camera, eye, s, reuse, points_.data(), out);
    PVR_CUDA_CHECK_LAUNCH("eyeRays");
    timers.rays[s]->stop(stream);
    timers.density[s]->start(stream);
    if (sparse) {
      size_t bytes = temp_.capacity();
      PVR_CUDA_CHECK(cub::DeviceSelect::If(temp_.data(), bytes, thrust::counting_iterator<uint32_t>(0),
                                           estimateList_.data(), estimateCount_.data(), int(pixels),
                                           NeedsEstimate{points_.data()}, stream));
      storeWithoutEstimateKernel<<<blocksFor(pixels, 256), 256, 0, stream>>>(points_.data(), uint32_t(pixels), s,
                                                                            params.samplesPerPixel, image);
      PVR_CUDA_CHECK_LAUNCH("storeWithoutEstimate");
      warpPerPointDensityKernel<<<unsigned(multiprocessorCount()) * 8u, 256, 0, stream>>>(*map.grid, params.density.radius, points_.data(),
                                                                         estimateList_.data(), estimateCount_.data(), s,
                                                                         params.samplesPerPixel, image);
      PVR_CUDA_CHECK_LAUNCH("warpPerPointDensity");
    } else if (options.kernel == DensityKernel::Hybrid) {
      if (map.grid) {
        if (knn) launchDensity<Estimator::Knn>(*map.grid, params.density, points_.data(), camera, s, params.samplesPerPixel, image, stream);
        else launchDensity<Estimator::Radius>(*map.grid, params.density, points_.data(), camera, s, params.samplesPerPixel, image, stream);
      } else {
        if (knn) launchDensity<Estimator::Knn>(*map.tree, params.density, points_.data(), camera, s, params.samplesPerPixel, image, stream);
        else launchDensity<Estimator::Radius>(*map.tree, params.density, points_.data(), camera, s, params.samplesPerPixel, image, stream);
      }
    } else if (options.kernel == DensityKernel::SharedMemory) {
      auto* kernel = knn ? sharedDensityKernel<Estimator::Knn> : sharedDensityKernel<Estimator::Radius>;
      kernel<<<tileGrid(camera.width, camera.height), dim3(kTile, kTile), 0, stream>>>(
          *map.grid, params.density, points_.data(), camera.width, camera.height, s, params.samplesPerPixel, image);
      PVR_CUDA_CHECK_LAUNCH("sharedDensity");
    } else {
      cellKeysOfPointsKernel<<<blocksFor(pixels, 256), 256, 0, stream>>>(*map.grid, points_.data(), uint32_t(pixels),
                                                                          noCell, sortKeys_[0].data(), sortValues_[0].data());
      PVR_CUDA_CHECK_LAUNCH("cellKeysOfPoints");
      cub::DoubleBuffer<uint32_t> k(sortKeys_[0].data(), sortKeys_[1].data()), v(sortValues_[0].data(), sortValues_[1].data());
      size_t bytes = temp_.capacity();
      PVR_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp_.data(), bytes, k, v, int(pixels), 0, endBit, stream));
      auto* kernel = knn ? sortedDensityKernel<Estimator::Knn> : sortedDensityKernel<Estimator::Radius>;
      kernel<<<blocksFor(pixels, 128), 128, 0, stream>>>(*map.grid, params.density, points_.data(), v.Current(),
                                                         uint32_t(pixels), s, params.samplesPerPixel, image);
      PVR_CUDA_CHECK_LAUNCH("sortedDensity");
    }
    timers.density[s]->stop(stream);
  }
}

void GpuGather::downloadShadedVertices(uint32_t host[2], cudaStream_t stream) const {
  PVR_CUDA_CHECK(cudaMemcpyAsync(host, vertexCount_.data(), 2 * sizeof(uint32_t), cudaMemcpyDeviceToHost, stream));
}

void GpuGather::renderFoveatedEye(const DeviceScene& scene, DeviceMap map, const RenderOptions& options,
                                  const StereoRig& rig, Eye eye, const DeviceMaskView& mask, cudaStream_t stream,
                                  EyeTimers& timers, EventTimer& reconstruct) {
  const EyeCamera camera = rig.eye(eye);
  const size_t pixels = size_t(camera.width) * camera.height;
  const GatherParams& params = options.gather;
  const bool knn = params.density.estimator == Estimator::Knn;
  int gazeX, gazeY;
  options.foveation.gazePixel(int(eye), camera.width, camera.height, gazeX, gazeY);
  images_[int(eye)].reserve(pixels, "eye image");
  inverseDepth_[int(eye)].reserve(pixels, "eye depths");
  sampleSpacing_[int(eye)].reserve(pixels, "eye sample spacing");
  vertexUsed_.reserve(mask.vertexCount, "mask vertices in use");
  vertexList_.reserve(mask.vertexCount, "mask vertices to shade");
  vertexCount_.reserve(2, "mask vertices shaded");
  vertexPoints_.reserve(mask.vertexCount, "mask vertex gather points");
  vertexColours_.reserve(mask.vertexCount, "mask vertex colours");
  vertexInverseDepths_.reserve(mask.vertexCount, "mask vertex depths");
  uint32_t* count = vertexCount_.data() + int(eye);
  EyeOutputs out;
  const StereoReuseView reuse = prepareReuse(options, rig, eye, stream, out);
  size_t bytes = 0;
  thrust::counting_iterator<uint32_t> vertices(0);
  PVR_CUDA_CHECK(cub::DeviceSelect::If(nullptr, bytes, vertices, vertexList_.data(), count, int(mask.vertexCount),
                                       VertexInUse{vertexUsed_.data()}, stream));
  temp_.reserve(bytes, "mask vertex selection scratch");
  timers.prepare(1);

  timers.rays[0]->start(stream);
  PVR_CUDA_CHECK(cudaMemsetAsync(vertexUsed_.data(), 0, mask.vertexCount, stream));
  markUsedVerticesKernel<<<blocksFor(mask.triangleCount, 256), 256, 0, stream>>>(mask, gazeX, gazeY, camera.width,
                                                                               camera.height, vertexUsed_.data());
  PVR_CUDA_CHECK_LAUNCH("markUsedVertices");
  bytes = temp_.capacity();
  PVR_CUDA_CHECK(cub::DeviceSelect::If(temp_.data(), bytes, vertices, vertexList_.data(), count, int(mask.vertexCount),
                                       VertexInUse{vertexUsed_.data()}, stream));
  auto* vertexRays = out.reusedCount ? vertexRaysKernel<StereoRole::Reuser>
                     : out.surfaces  ? vertexRaysKernel<StereoRole::Source>
                                     : vertexRaysKernel<StereoRole::Alone>;
  vertexRays<<<blocksFor(mask.vertexCount, 128), 128, 0, stream>>>(scene.view, scene.intersector, params, camera, eye,
                                                                   mask, gazeX, gazeY, vertexList_.data(), count, reuse,
                                                                   out, vertexPoints_.data(), vertexInverseDepths_.data());
  PVR_CUDA_CHECK_LAUNCH("vertexRays");
  timers.rays[0]->stop(stream);

  timers.density[0]->start(stream);
  // One warp per vertex, also for Geisler-Perry's ~300k: one thread per vertex was measured
  // slower there on the H100 (6.0 against 4.5 ms for both eyes' pass).
  if (map.grid && !knn) {
    warpPerPointDensityKernel<<<unsigned(multiprocessorCount()) * 8u, 256, 0, stream>>>(*map.grid, params.density.radius,
                                                                       vertexPoints_.data(), vertexList_.data(), count,
                                                                       0, 1, vertexColours_.data());
  } else if (map.grid) {
    listedDensityKernel<HashGridView, Estimator::Knn><<<blocksFor(mask.vertexCount, 128), 128, 0, stream>>>(
        *map.grid, params.density, vertexPoints_.data(), vertexList_.data(), count, vertexColours_.data());
  } else if (knn) {
    listedDensityKernel<KdTreeView, Estimator::Knn><<<blocksFor(mask.vertexCount, 128), 128, 0, stream>>>(
        *map.tree, params.density, vertexPoints_.data(), vertexList_.data(), count, vertexColours_.data());
  } else {
    listedDensityKernel<KdTreeView, Estimator::Radius><<<blocksFor(mask.vertexCount, 128), 128, 0, stream>>>(
        *map.tree, params.density, vertexPoints_.data(), vertexList_.data(), count, vertexColours_.data());
  }
  PVR_CUDA_CHECK_LAUNCH("vertexDensity");
  timers.density[0]->stop(stream);

  reconstruct.start(stream);
  // A gaze inside the image leaves no pixel uncovered; these are for the rest.
  PVR_CUDA_CHECK(cudaMemsetAsync(images_[int(eye)].data(), 0, pixels * sizeof(Vec3), stream));
  PVR_CUDA_CHECK(cudaMemsetAsync(inverseDepth_[int(eye)].data(), 0, pixels * sizeof(float), stream));
  thrust::fill_n(thrust::cuda::par.on(stream), sampleSpacing_[int(eye)].data(), pixels, 1.0f);  // as on the CPU
  const VertexValues values{vertexColours_.data(), vertexInverseDepths_.data()};
  const RasterTarget target{images_[int(eye)].data(), inverseDepth_[int(eye)].data(), sampleSpacing_[int(eye)].data(),
                            camera.width, camera.height};
  if (mask.smallCount)
    rasterKernel<1><<<blocksFor(mask.smallCount, 256), 256, 0, stream>>>(mask, mask.smallTriangles, mask.smallCount,
                                                                         gazeX, gazeY, values, target);
  if (mask.largeCount)
    rasterKernel<32><<<blocksFor(size_t(mask.largeCount) * 32, 256), 256, 0, stream>>>(
        mask, mask.largeTriangles, mask.largeCount, gazeX, gazeY, values, target);
  PVR_CUDA_CHECK_LAUNCH("raster");
  reconstruct.stop(stream);
}

static double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

RayThroughput measureRayThroughput(const DeviceScene& scene, const StereoRig& rig, int repeats, cudaStream_t stream) {
  RayThroughput out;
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
      primaryRaysKernel<<<grid, block, 0, stream>>>(scene.intersector, camera, primary[e].data());
      PVR_CUDA_CHECK_LAUNCH("primaryRays");
      timer.stop(stream);
      primaryMs += timer.ms();
      timer.start(stream);
      shadowRaysKernel<<<grid, block, 0, stream>>>(scene.view, scene.intersector, camera, primary[e].data(), occluded.data());
      PVR_CUDA_CHECK_LAUNCH("shadowRays");
      timer.stop(stream);
      shadowMs += timer.ms();
      timer.start(stream);
      diffuseRaysKernel<<<grid, block, 0, stream>>>(scene.view, scene.intersector, camera, primary[e].data(), secondary.data());
      PVR_CUDA_CHECK_LAUNCH("diffuseRays");
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
  out.primaryHits = std::move(hits);  // the left eye's, downloaded last
  return out;
}

}  // namespace pvr::cuda
