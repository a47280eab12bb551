#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_select.cuh>
#include <thrust/iterator/counting_iterator.h>
#include <type_traits>

#include "pvr/cuda/density.cuh"
#include "pvr/cuda/eye_kernels.cuh"
#include "pvr/cuda/surface_cache.cuh"
#include "pvr/photon/deferred_shadows.h"

namespace pvr::cuda {
namespace {

// The paper's "single" scheme: eye ray and estimate in one kernel.
template <class Map, Estimator E, StereoRole R>
__global__ void singleKernel(SceneView scene, SceneIntersector sceneIntersector, Map map, GatherParams params,
                             EyeCamera camera, Eye eye, StereoReuseView reuse, EyeOutputs out) {
  const SceneIntersector intersector = withSharedStack<kTile * kTile>(sceneIntersector);
  int x, y;
  if (!tilePixel(camera.width, camera.height, x, y)) return;
  params.density.estimator = E;  // compile-time estimator: the radius kernel carries no heap
  size_t pixel = size_t(y) * camera.width + x;
  PixelGuide guide;
  PixelSample s = shadePixel(scene, intersector, map, params, camera, eye, x, y, reuseFor<R>(reuse),
                             surfaceFor<R>(out, pixel), out.direct ? &guide : nullptr);
  out.image[pixel] = s.radiance;
  recordPixel(out, pixel, s);
  if (out.direct) {
    out.emitted[pixel] = guide.emitted, out.direct[pixel] = guide.direct;
    out.albedo[pixel] = guide.albedo, out.normal[pixel] = guide.normal;
  }
}

// The intersector the eye-rays kernel shades through: shadow queries answered from the deferred
// shadow kernel's results (Deferred), or traced in place.
template <bool Deferred>
__device__ inline auto shadingIntersector(const SceneIntersector& intersector, const DeferredShadowsView& shadows,
                                          size_t pixel) {
  if constexpr (Deferred) return ReplayedShadows<SceneIntersector>{intersector, shadows.blocked + pixel, shadows.pixels};
  else return intersector;
}

// Hybrid, first kernel: eye rays to their gather points (a reused pixel's carries its colour).
// At most 168 registers, so that 6 blocks stay on an SM: unbounded, the kernel took 204 and left
// 4 (12.5 % occupancy, ncu on Sponza, 2026-12-05), too few warps to hide its memory latency.
template <StereoRole R, bool Deferred>
__global__ void __launch_bounds__(kTile* kTile, 6) eyeRaysKernel(SceneView scene, SceneIntersector sceneIntersector, GatherParams params, EyeCamera camera,
                              Eye eye, int sample, StereoReuseView reuse, GatherPointStore points, EyeOutputs out,
                              DeferredShadowsView shadows) {
  const SceneIntersector intersector = withSharedStack<kTile * kTile>(sceneIntersector);
  int x, y;
  if (!tilePixel(camera.width, camera.height, x, y)) return;
  size_t pixel = size_t(y) * camera.width + x;
  PixelSample state;
  if (R == StereoRole::Reuser && sample > 0) state.reusedFrom = out.reusedFrom[pixel];  // sample 0 decided
  const GatherPoint point = pixelGatherPoint(scene, shadingIntersector<Deferred>(intersector, shadows, pixel), params, camera,
                                            eye, x, y, sample, reuseFor<R>(reuse), state, surfaceFor<R>(out, pixel));
  points.store(pixel, point);
  recordGuide(out, pixel, point, sample, params.samplesPerPixel);
  if (sample == 0) recordPixel(out, pixel, state);
}

// A reusing right eye under gather, first part (its first hits traced or rasterised already): each
// pixel's reuse decision; a reused pixel takes the left eye's colour here, the others are listed
// (by 8x8 tiles) for listedEyeRaysKernel. Over every pixel, the eye-rays kernel's warps waited on
// their few unreused pixels (14 % occupancy on Sibenik, ncu, H100). Later samples read sample 0's
// decision; the list stays.
__global__ void __launch_bounds__(kTile* kTile) reuseDecisionKernel(SceneView scene, SceneIntersector sceneIntersector,
                                                                     GatherParams params, EyeCamera camera, Eye eye,
                                                                     int sample, StereoReuseView reuse,
                                                                     GatherPointStore points, EyeOutputs out,
                                                                     uint32_t* shadeList, unsigned* shadeCount) {
  const SceneIntersector intersector = withSharedStack<kTile * kTile>(sceneIntersector);
  int x, y;
  const bool inside = tilePixel(camera.width, camera.height, x, y);
  const size_t pixel = inside ? size_t(y) * camera.width + x : 0;
  bool shade = false;
  if (inside) {
    PixelSample state;
    if (sample > 0) {
      state.reusedFrom = out.reusedFrom[pixel];
    } else {
      CounterRng rng(0, 0, 0);
      const Ray ray = pixelSampleRay(params, camera, eye, x, y, 0, rng);
      recordFirstHit(scene, camera, ray, sampleZeroFirstHit(scene, intersector, params, x, y, ray), reuse, state);
      recordPixel(out, pixel, state);
    }
    if (state.reusedFrom != kNotReused) {
      const GatherPoint reused = reusedGatherPoint(reuse, state.reusedFrom);
      points.store(pixel, reused);
      recordGuide(out, pixel, reused, sample, params.samplesPerPixel);
    }
    shade = state.reusedFrom == kNotReused;
  }
  if (sample == 0) appendInBlock<kTile * kTile>(shadeList, shadeCount, shade, uint32_t(pixel));
}

// A reusing right eye under gather, second part: the listed pixels, shaded as an eye of its own
// would (the decision is made; the random numbers are separate rendering's).
__global__ void __launch_bounds__(kTile* kTile, 6) listedEyeRaysKernel(SceneView scene, SceneIntersector sceneIntersector,
                                                                      GatherParams params, EyeCamera camera, Eye eye,
                                                                      int sample, GatherPointStore points, EyeOutputs out,
                                                                      const uint32_t* shadeList, const unsigned* shadeCount) {
  const SceneIntersector intersector = withSharedStack<kTile * kTile>(sceneIntersector);
  const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
  const bool shaded = i < *shadeCount;
  const uint32_t pixel = shaded ? shadeList[i] : 0u;
  GatherPoint point;
  if (shaded) {
    const int x = int(pixel % unsigned(camera.width)), y = int(pixel / unsigned(camera.width));
    PixelSample state;
    point = pixelGatherPoint(scene, intersector, params, camera, eye, x, y, sample, StereoReuseView(), state);
  }
  finishShadingTogether();
  if (!shaded) return;
  points.store(pixel, point);
  recordGuide(out, pixel, point, sample, params.samplesPerPixel);
}

// Deferred shadows, first run (photon/deferred_shadows.h): the eye-rays kernel's gathering code,
// its shading thrown away, to record the shadow queries it asks.
template <StereoRole R>
__global__ void __launch_bounds__(kTile* kTile, 6) recordShadowsKernel(SceneView scene, SceneIntersector sceneIntersector,
                                                                      GatherParams params, EyeCamera camera, Eye eye,
                                                                      int sample, StereoReuseView reuse, EyeOutputs out,
                                                                      DeferredShadowsView shadows) {
  const SceneIntersector intersector = withSharedStack<kTile * kTile>(sceneIntersector);
  int x, y;
  if (!tilePixel(camera.width, camera.height, x, y)) return;
  const size_t pixel = size_t(y) * camera.width + x;
  PixelSample state;
  if (R == StereoRole::Reuser && sample > 0) state.reusedFrom = out.reusedFrom[pixel];
  const RecordedShadows<SceneIntersector> recorder{intersector, shadows.queries + pixel, shadows.pixels};
  pixelGatherPoint(scene, recorder, params, camera, eye, x, y, sample, reuseFor<R>(reuse), state);
  shadows.asked[pixel] = uint8_t(recorder.recorded());
}

// Deferred shadows: query blockIdx.z of every pixel, traced by a kernel with few registers, a block
// per 8x8 tile as the standalone shadow rays (whose rays from neighbouring surface points stay
// coherent: 128 pixels of one row took 3.51 ms against 3.02 for Sibenik's left eye, ncu, H100).
__global__ void __launch_bounds__(kTile* kTile) shadowQueriesKernel(SceneIntersector sceneIntersector, int width,
                                                                     int height, DeferredShadowsView shadows) {
  const SceneIntersector intersector = withSharedStack<kTile * kTile>(sceneIntersector);
  int x, y;
  if (tilePixel(width, height, x, y)) answerShadowQuery(intersector, shadows, int(blockIdx.z), size_t(y) * width + x);
}

// Sample 0's first hits, before the eye-rays kernel shades from them (PrimaryHitsView::traced).
// The camera rays are a quarter to a third of an eye pass's rays (Sibenik: 1 of 3-4); traced here
// with 72 registers (44 % occupancy, against the eye kernel's 168 and 19 %), they run near the
// standalone ray rate (Sibenik: 0.54 ms an eye, ncu, H100).
__global__ void __launch_bounds__(kTile* kTile) firstHitsKernel(SceneIntersector sceneIntersector, GatherParams params,
                                                                 EyeCamera camera, Eye eye, Hit* hits) {
  const SceneIntersector intersector = withSharedStack<kTile * kTile>(sceneIntersector);
  int x, y;
  if (!tilePixel(camera.width, camera.height, x, y)) return;
  hits[size_t(y) * camera.width + x] = pixelFirstHit(intersector, params, camera, eye, x, y);
}

// A kernel template's instance for a stereo role, `pick(role constant)`: the role is a template
// argument, so an eye that neither records nor reuses surfaces compiles those tests away.
template <class Pick>
auto byRole(StereoRole role, Pick pick) {
  switch (role) {
    case StereoRole::Reuser: return pick(std::integral_constant<StereoRole, StereoRole::Reuser>{});
    case StereoRole::Source: return pick(std::integral_constant<StereoRole, StereoRole::Source>{});
    default: return pick(std::integral_constant<StereoRole, StereoRole::Alone>{});
  }
}

template <Estimator E, class Map>
void launchSingle(const DeviceScene& scene, const Map& map, const GatherParams& params, const EyeCamera& camera,
                  Eye eye, StereoRole role, const StereoReuseView& reuse, const EyeOutputs& out, cudaStream_t stream) {
  auto* kernel = byRole(role, [](auto r) { return singleKernel<Map, E, decltype(r)::value>; });
  launch("eye rays + density (single kernel)", kernel, tileGrid(camera.width, camera.height), dim3(kTile, kTile), 0,
         stream, scene.view, scene.intersector, map, params, camera, eye, reuse, out);
}

template <Estimator E>
void dispatchSingle(const DeviceScene& scene, DeviceMap map, const GatherParams& params, const EyeCamera& camera,
                    Eye eye, StereoRole role, const StereoReuseView& reuse, const EyeOutputs& out, cudaStream_t stream) {
  if (map.grid) launchSingle<E>(scene, *map.grid, params, camera, eye, role, reuse, out, stream);
  else launchSingle<E>(scene, *map.tree, params, camera, eye, role, reuse, out, stream);
}

}  // namespace

StereoReuseView GpuEyePass::prepareReuse(const EyePass& pass, cudaStream_t stream, EyeOutputs& out) {
  StereoReuseView reuse;
  if (pass.role == StereoRole::Alone) return reuse;
  const size_t pixels = size_t(pass.camera.width) * pass.camera.height;
  if (pass.role == StereoRole::Source) {
    surfaces_.reserve(pixels, "left-eye surfaces");
    // Foveated, only the vertices' pixels are recorded: the rest must read as not reusable.
    if (pass.foveated())
      PVR_CUDA_CHECK(cudaMemsetAsync(surfaces_.data(), 0xff, pixels * sizeof(SurfaceRecord), stream));
    out.surfaces = surfaces_.data();
    return reuse;
  }
  reuse = reuseViewFor(pass, surfaces_.data(), images_[int(Eye::Left)].data(), scattered_.data());
  reusedCount_.reserve(1, "reuse count");
  PVR_CUDA_CHECK(cudaMemsetAsync(reusedCount_.data(), 0, sizeof(unsigned), stream));
  out.reusedCount = reusedCount_.data();
  if (!pass.foveated()) {  // foveated reuse is per vertex: no per-pixel sources
    reusedFrom_.reserve(pixels, "reuse sources");
    out.reusedFrom = reusedFrom_.data();
  }
  return reuse;
}

size_t GpuEyePass::memoryBytes() const {
  size_t bytes = points_.bytes() + firstHits_.bytes() + shadowQueries_.bytes() + shadowsAsked_.bytes() +
                 shadowsBlocked_.bytes() + temp_.bytes() + surfaces_.bytes() + scattered_.bytes() + reusedFrom_.bytes() +
                 reusedCount_.bytes() + shadeList_.bytes() + shadeCount_.bytes() + estimateList_.bytes() +
                 estimateCount_.bytes() + vertexUsed_.bytes() +
                 vertexList_.bytes() + vertexCount_.bytes() + vertexPoints_.bytes() + vertexColours_.bytes() +
                 vertexInverseDepths_.bytes();
  for (int i = 0; i < 2; ++i)
    bytes += images_[i].bytes() + firstPrim_[i].bytes() + inverseDepth_[i].bytes() + sampleSpacing_[i].bytes() +
             sortKeys_[i].bytes() + sortValues_[i].bytes() + emitted_[i].bytes() + direct_[i].bytes() + albedo_[i].bytes() + normal_[i].bytes();
  return bytes;
}

void GpuEyePass::downloadReusedCount(unsigned* host, cudaStream_t stream) const {
  PVR_CUDA_CHECK(cudaMemcpyAsync(host, reusedCount_.data(), sizeof(unsigned), cudaMemcpyDeviceToHost, stream));
}

void GpuEyePass::render(const DeviceScene& scene, DeviceMap map, const EyePass& pass, cudaStream_t stream,
                        StageClock& clock) {
  const Eye eye = pass.eye;
  const int e = int(eye);
  const EyeCamera& camera = pass.camera;
  const size_t pixels = size_t(camera.width) * camera.height;
  GatherParams params = pass.gather;
  const bool knn = params.density.estimator == Estimator::Knn;
  Vec3* image = (images_[e].reserve(pixels, "eye image"), images_[e].data());
  EyeOutputs out;
  out.image = image;
  out.firstPrim = (firstPrim_[e].reserve(pixels, "first-hit ids"), firstPrim_[e].data());
  out.inverseDepth = (inverseDepth_[e].reserve(pixels, "eye depths"), inverseDepth_[e].data());
  if (pass.denoiseGuides) {
    out.emitted = (emitted_[e].reserve(pixels, "denoiser emitted light"), emitted_[e].data());
    out.direct = (direct_[e].reserve(pixels, "denoiser direct light"), direct_[e].data());
    out.albedo = (albedo_[e].reserve(pixels, "denoiser albedo"), albedo_[e].data());
    out.normal = (normal_[e].reserve(pixels, "denoiser normals"), normal_[e].data());
  }
  StereoReuseView reuse = prepareReuse(pass, stream, out);

  const bool cached = pass.density == DensityScheme::SurfaceCache;  // eye rays, then the cache: no kernel choice
  if (pass.kernel == DensityKernel::Single && !cached) {  // shadePixel loops over the samples itself
    StageScope scope(clock, Stage::EyeRays, e);
    if (knn) dispatchSingle<Estimator::Knn>(scene, map, params, camera, eye, pass.role, reuse, out, stream);
    else dispatchSingle<Estimator::Radius>(scene, map, params, camera, eye, pass.role, reuse, out, stream);
    return;
  }

  points_.reserve(pixels, "gather points");
  // Scatter's reuser takes most pixels from the left eye before any ray: no pre-pass for those.
  const bool scatterReuser = pass.role == StereoRole::Reuser && pass.reuse == StereoMode::Scatter;
  const bool apart = pass.raySchedule == RaySchedule::FirstHits || pass.raySchedule == RaySchedule::Deferred;
  if (apart && !params.primary.present() && !scatterReuser) {
    firstHits_.reserve(pixels, "first hits");
    StageScope scope(clock, Stage::EyeRays, e);
    launch("first hits", firstHitsKernel, tileGrid(camera.width, camera.height), dim3(kTile, kTile), 0, stream,
           scene.intersector, params, camera, eye, firstHits_.data());
    params.primary.traced = firstHits_.data();
    params.primary.width = camera.width;
  }
  const bool sparse = !cached && pass.role == StereoRole::Reuser && map.grid && !knn;  // few points left to estimate
  const bool sorted = !cached && pass.kernel == DensityKernel::CellSorted && !sparse;
  if (cached) map.surfaceCache->prepare(pass.cacheCellSize, 2 * pixels * size_t(params.samplesPerPixel), stream);  // both eyes' points
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
                                         estimateCount_.data(), int(pixels), NeedsEstimate{points_.view()}, stream));
    temp_.reserve(bytes, "gather-point selection scratch");
  }
  const bool deferred = pass.raySchedule == RaySchedule::Deferred;
  // A reusing right eye under gather whose first hits come from a pre-pass shades over a list of
  // the pixels it does not reuse, where its schedule asks for first hits apart (Auto's choice
  // from two shadow queries a point, frame_options.h), with traced and rasterised first hits
  // alike.
  const bool listed = pass.role == StereoRole::Reuser && pass.reuse == StereoMode::Gather &&
                      pass.raySchedule == RaySchedule::FirstHits && !pass.foveated() &&
                      (params.primary.traced || params.primary.present());
  if (listed) {
    shadeList_.reserve(pixels, "right-eye pixels to shade");
    shadeCount_.reserve(1, "right-eye pixels to shade");
    PVR_CUDA_CHECK(cudaMemsetAsync(shadeCount_.data(), 0, sizeof(unsigned), stream));
  }
  DeferredShadowsView shadows;
  if (deferred) {
    shadowQueries_.reserve(kMaxDeferredShadows * pixels, "deferred shadow queries");
    shadowsAsked_.reserve(pixels, "deferred shadow counts");
    shadowsBlocked_.reserve(kMaxDeferredShadows * pixels, "deferred shadow answers");
    shadows = DeferredShadowsView{shadowQueries_.data(), shadowsAsked_.data(), shadowsBlocked_.data(), pixels};
  }
  auto* eyeRays = byRole(pass.role, [deferred](auto r) {
    return deferred ? eyeRaysKernel<decltype(r)::value, true> : eyeRaysKernel<decltype(r)::value, false>;
  });
  auto* recordShadows = byRole(pass.role, [](auto r) { return recordShadowsKernel<decltype(r)::value>; });
  const int samples = params.samplesPerPixel;
  for (int s = 0; s < samples; ++s) {
    {
      StageScope scope(clock, Stage::EyeRays, e);
      if (deferred) {
        launch("record shadow queries", recordShadows, tileGrid(camera.width, camera.height), dim3(kTile, kTile), 0, stream,
               scene.view, scene.intersector, params, camera, eye, s, reuse, out, shadows);
        dim3 grid = tileGrid(camera.width, camera.height);
        grid.z = kMaxDeferredShadows;
        launch("shadow queries", shadowQueriesKernel, grid, dim3(kTile, kTile), 0, stream, scene.intersector, camera.width,
               camera.height, shadows);
      }
      if (listed) {
        launch("reuse decisions", reuseDecisionKernel, tileGrid(camera.width, camera.height), dim3(kTile, kTile), 0,
               stream, scene.view, scene.intersector, params, camera, eye, s, reuse, points_.view(), out,
               shadeList_.data(), shadeCount_.data());
        // As many blocks as the whole eye would take; those past the list's end return at once.
        launch("eye rays (pixels not reused)", listedEyeRaysKernel, blocksFor(pixels, kTile * kTile),
               unsigned(kTile * kTile), 0, stream, scene.view, scene.intersector, params, camera, eye, s,
               points_.view(), out, shadeList_.data(), shadeCount_.data());
      } else {
        launch("eye rays", eyeRays, tileGrid(camera.width, camera.height), dim3(kTile, kTile), 0, stream, scene.view,
               scene.intersector, params, camera, eye, s, reuse, points_.view(), out, shadows);
      }
    }
    StageScope scope(clock, Stage::Density, e);
    if (cached) {
      map.surfaceCache->estimate(map, params.density, points_.view(), uint32_t(pixels), s, samples, image, stream);
    } else if (sparse) {
      size_t bytes = temp_.capacity();
      PVR_CUDA_CHECK(cub::DeviceSelect::If(temp_.data(), bytes, thrust::counting_iterator<uint32_t>(0),
                                           estimateList_.data(), estimateCount_.data(), int(pixels),
                                           NeedsEstimate{points_.view()}, stream));
      storeWithoutEstimate(points_.view(), uint32_t(pixels), s, samples, image, stream);
      estimateWarpPerPoint(*map.grid, params.density.radius, points_.view(), estimateList_.data(), estimateCount_.data(),
                           s, samples, image, stream);
    } else if (pass.kernel == DensityKernel::Hybrid) {
      estimateTiled(map, params.density, points_.view(), camera.width, camera.height, s, samples, image, stream);
    } else if (pass.kernel == DensityKernel::SharedMemory) {
      estimateSharedMemory(*map.grid, params.density, points_.view(), camera.width, camera.height, s, samples, image,
                           stream);
    } else {
      writeCellKeysOfPoints(*map.grid, points_.view(), uint32_t(pixels), noCell, sortKeys_[0].data(),
                            sortValues_[0].data(), stream);
      cub::DoubleBuffer<uint32_t> k(sortKeys_[0].data(), sortKeys_[1].data()), v(sortValues_[0].data(), sortValues_[1].data());
      size_t bytes = temp_.capacity();
      PVR_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp_.data(), bytes, k, v, int(pixels), 0, endBit, stream));
      estimateInOrder(*map.grid, params.density, points_.view(), v.Current(), uint32_t(pixels), s, samples, image, stream);
    }
  }
}

}  // namespace pvr::cuda
