#include "pvr/cuda/cuda_frame_backend.h"

#include <cuda_runtime.h>

#include <algorithm>
#include <cstring>

#include "pvr/accel/wide_bvh.h"
#include "pvr/cuda/cuda_stage_clock.h"
#include "pvr/cuda/denoise.cuh"
#include "pvr/cuda/device_wide_bvh.h"
#include "pvr/cuda/display_handover.h"
#include "pvr/cuda/eye_pass.cuh"
#include "pvr/cuda/injected_fault.cuh"
#include "pvr/cuda/photon_map_build.cuh"
#include "pvr/cuda/photon_trace.cuh"
#include "pvr/cuda/surface_cache.cuh"
#include "pvr/cuda/temporal.cuh"
#include "pvr/foveation/mask.h"
#include "pvr/raster/gbuffer_raster.h"
#include "pvr/scene/scene.h"
#include "pvr/util/fault_injection.h"

namespace pvr {

bool cudaDeviceUsable(std::string* why) {
  int count = 0;
  cudaError_t status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess || count == 0) {
    if (why)
      *why = status == cudaSuccess ? std::string("no CUDA GPU is present")
                                   : std::string("no usable CUDA GPU (") + cudaGetErrorString(status) + ")";
    cudaGetLastError();
    return false;
  }
  return true;
}

struct CudaFrameBackend::Impl {
  const Scene& scene;
  Bvh bvh;
  cudaStream_t stream = nullptr;
  cudaDeviceProp properties{};
  cuda::DeviceScene deviceScene;
  cuda::GpuPhotonTracer tracer;
  // The photon pass's 8-wide BVH (setPhotonPassBvh), uploaded at first use.
  cuda::DeviceWideBvh wide;
  bool wideInUse = false;
  uint32_t tracePhotons(const PhotonTraceParams& params) {
    return wideInUse ? tracer.trace(deviceScene, wide.intersector, params, stream) : tracer.trace(deviceScene, params, stream);
  }
  cuda::RollingPhotons rolling;
  bool rollingInUse = false;  ///< the map is built over the rolling slices, not the last trace
  const Photon* mapPhotons() const { return rollingInUse ? rolling.photons() : tracer.photons(); }
  uint32_t mapPhotonCount() const { return rollingInUse ? rolling.count() : tracer.count(); }
  const Bounds3& mapBounds() const { return rollingInUse ? rolling.bounds() : tracer.bounds(); }
  cuda::GpuHashGrid grid;
  cuda::GpuKdTree tree;
  PhotonMapKind mapKind = PhotonMapKind::HashGrid;
  HashGridView gridView;
  KdTreeView treeView;
  cuda::GpuSurfaceCache surfaceCache;  ///< over the map, for both eyes (DensityScheme::SurfaceCache)
  cuda::GpuEyePass eyePass;
  cuda::GpuDenoiser denoiser;
  cuda::GpuTemporal temporal;
  std::unique_ptr<cuda::CudaStageClock> clock;
  // The G-buffer pre-pass: Vulkan on this GPU, its buffer and semaphores imported (made at first use).
  struct Raster {
    std::unique_ptr<VulkanContext> vulkan;
    std::unique_ptr<GBufferRaster> pass;
    std::unique_ptr<cuda::SharedBuffer> buffer;
    uint64_t generation = 0;
    std::unique_ptr<cuda::SharedSemaphore> done, readersDone;
    bool readersSignalled = false;  ///< CUDA signalled readersDone after the last frame's reads
  } raster;
  cuda::EventTimer benchTimer;
  // What this frame did, for finishFrame() and readEye().
  struct FrameState {
    bool rendered[2] = {false, false}, foveated[2] = {false, false}, temporal = false, reused = false, cached = false,
         rasterised = false;
    size_t pixels[2] = {0, 0};
    int width[2] = {0, 0}, height[2] = {0, 0};
  } frame;
  // The foveation mask last used, uploaded once and keyed on its content id.
  uint64_t maskId = 0;
  uint32_t maskVertices = 0, maskTriangleCount = 0;
  cuda::DeviceBuffer<MaskPoint> maskOffsets;
  cuda::DeviceBuffer<uint32_t> maskTriangles, maskTrianglesBySize;
  uint32_t smallTriangles = 0;

  explicit Impl(const Scene& s) : scene(s), bvh(Bvh::build(s)) {
    PVR_CUDA_CHECK(cudaGetDeviceProperties(&properties, 0));
    PVR_CUDA_CHECK(cudaStreamCreateWithFlags(&stream, cudaStreamNonBlocking));
    clock = std::make_unique<cuda::CudaStageClock>(stream);
    deviceScene.upload(scene, bvh);
  }
  ~Impl() {
    cudaStreamSynchronize(stream);  // nothing reads the imported G-buffer any more
    raster.buffer.reset();
    raster.done.reset();
    raster.readersDone.reset();
    raster.pass.reset();
    raster.vulkan.reset();
    cudaStreamDestroy(stream);
  }

  PrimaryHitsView primaryHits(Eye eye) const {
    return gbufferEyeView(raster.buffer->data(), raster.pass->width(), raster.pass->height(), eye);
  }

  cuda::DeviceMap map() {
    cuda::DeviceMap m;
    m.surfaceCache = &surfaceCache;
    if (mapKind == PhotonMapKind::HashGrid) m.grid = &gridView;
    else m.tree = &treeView;
    return m;
  }

  cuda::DeviceMaskView uploadMask(const FoveationMask& mask) {
    if (mask.id == 0 || mask.id != maskId) {
      maskOffsets.upload(mask.offsets.data(), mask.offsets.size(), "foveation mask vertices", stream);
      maskTriangles.upload(mask.triangles.data(), mask.triangles.size(), "foveation mask triangles", stream);
      std::vector<uint32_t> small, large;
      for (size_t t = 0; t < mask.triangleCount(); ++t) {  // sized at a central gaze: a load-balancing hint
        int w, h;
        triangleBoxSize(mask.offsets.data(), mask.triangles.data(), t, mask.params.width / 2, mask.params.height / 2, w, h);
        (int64_t(w) * h <= cuda::kSmallTrianglePixels ? small : large).push_back(uint32_t(t));
      }
      smallTriangles = uint32_t(small.size());
      small.insert(small.end(), large.begin(), large.end());
      maskTrianglesBySize.upload(small.data(), small.size(), "foveation mask triangles by size", stream);
      PVR_CUDA_CHECK(cudaStreamSynchronize(stream));  // the host lists go out of scope
      maskId = mask.id;
      maskVertices = uint32_t(mask.offsets.size());
      maskTriangleCount = uint32_t(mask.triangleCount());
    }
    // Everything from the uploaded copy, nothing from the live mask.
    cuda::DeviceMaskView view{maskOffsets.data(), maskTriangles.data(), maskVertices, maskTriangleCount};
    view.smallTriangles = maskTrianglesBySize.data();
    view.largeTriangles = maskTrianglesBySize.data() + smallTriangles;
    view.smallCount = smallTriangles;
    view.largeCount = maskTriangleCount - smallTriangles;
    return view;
  }
};

CudaFrameBackend::CudaFrameBackend(const Scene& scene) {
  std::string why;
  if (!cudaDeviceUsable(&why)) throw Error("the CUDA backend cannot run: " + why);
  impl_ = std::make_unique<Impl>(scene);
}

CudaFrameBackend::~CudaFrameBackend() = default;

std::string CudaFrameBackend::deviceName() const {
  const cudaDeviceProp& p = impl_->properties;
  return std::string(p.name) + " (sm_" + std::to_string(p.major) + std::to_string(p.minor) + ", " +
         std::to_string(p.multiProcessorCount) + " SMs, " + std::to_string(p.totalGlobalMem >> 30) + " GiB)";
}

StageClock& CudaFrameBackend::clock() { return *impl_->clock; }
const BvhBuildStats& CudaFrameBackend::bvhStats() const { return impl_->bvh.stats(); }
size_t CudaFrameBackend::deviceBytes() const { return cuda::deviceBytesInUse(); }
const cuda::DeviceScene& CudaFrameBackend::deviceScene() const { return impl_->deviceScene; }
CUstream_st* CudaFrameBackend::stream() const { return impl_->stream; }

size_t CudaFrameBackend::tracePhotons(const PhotonTraceParams& params, int slot, int slots) {
  Impl& m = *impl_;
  m.frame = Impl::FrameState();
  const uint32_t traced = m.tracePhotons(params);
  m.rollingInUse = slots > 1;
  if (!m.rollingInUse) return traced;
  m.rolling.store(slot, slots, m.tracer.photons(), traced, m.tracer.bounds(), m.stream);
  return m.rolling.count();
}

size_t CudaFrameBackend::buildPhotonMap(PhotonMapKind kind, float radius) {
  Impl& m = *impl_;
  m.mapKind = kind;
  m.surfaceCache.invalidate();
  if (kind == PhotonMapKind::HashGrid) {
    m.grid.build(m.mapPhotons(), m.mapPhotonCount(), m.mapBounds(), radius, m.stream);
    m.gridView = m.grid.view();
    return m.grid.memoryBytes();
  }
  m.tree.build(m.mapPhotons(), m.mapPhotonCount(), m.stream);
  m.treeView = m.tree.view();
  return m.tree.memoryBytes();
}

void CudaFrameBackend::rasterizePrimary(const EyeCamera eyes[2]) {
  Impl& m = *impl_;
  Impl::Raster& r = m.raster;
  if (!r.pass) {  // made whole or not at all: a failure leaves nothing half set up
    Impl::Raster made;
    VulkanContextOptions options;
    options.hasPreferredUuid = cuda::currentDeviceUuid(options.preferredUuid);
    try {
      made.vulkan = std::make_unique<VulkanContext>(options);
    } catch (const Error& e) {
      throw Error(std::string("--primary raster: ") + e.what());
    }
    if (!options.hasPreferredUuid || std::memcmp(made.vulkan->deviceUuid(), options.preferredUuid, 16) != 0)
      throw Error("--primary raster: Vulkan found no device that is the CUDA GPU (it found '" + made.vulkan->deviceName() + "')");
    made.pass = std::make_unique<GBufferRaster>(*made.vulkan, m.scene, true);
    made.done = std::make_unique<cuda::SharedSemaphore>(made.pass->exportRasterDoneFd());
    made.readersDone = std::make_unique<cuda::SharedSemaphore>(made.pass->exportReadersDoneFd());
    r = std::move(made);
  }
  r.pass->render(eyes, r.readersSignalled);
  r.readersSignalled = false;
  if (r.pass->bufferGeneration() != r.generation) {  // a new buffer (first use, new eye size): import it
    r.buffer.reset();
    r.buffer = std::make_unique<cuda::SharedBuffer>(r.pass->exportBufferFd(), r.pass->bufferAllocationBytes(), r.pass->bufferBytes());
    r.generation = r.pass->bufferGeneration();
  }
  r.done->wait(m.stream);
  m.frame.rasterised = true;
}

void CudaFrameBackend::scatter(const EyeCamera& /*source: the records hold world positions*/, const EyeCamera& target) {
  impl_->eyePass.scatter(impl_->deviceScene, target, impl_->stream);
}

void CudaFrameBackend::renderEye(const EyePass& pass) {
  Impl& m = *impl_;
  const int e = int(pass.eye);
  m.frame.rendered[e] = true;
  m.frame.foveated[e] = pass.foveated();
  m.frame.pixels[e] = size_t(pass.camera.width) * pass.camera.height;
  m.frame.width[e] = pass.camera.width, m.frame.height[e] = pass.camera.height;
  m.frame.reused = m.frame.reused || pass.role == StereoRole::Reuser;
  m.frame.cached = m.frame.cached || (pass.density == DensityScheme::SurfaceCache && !pass.foveated());
  if (faultInjected(Fault::GpuKernelFault)) cuda::launchInjectedFault(m.stream);
  EyePass p = pass;
  if (p.raySchedule == RaySchedule::Auto)
    p.raySchedule = eyeRayScheduleFor(shadowQueriesPerPoint(m.scene.view(), p.gather.punctualShadowRays),
                                      p.role == StereoRole::Reuser);
  if (pass.rasterPrimary) {
    if (!m.frame.rasterised) throw Error("frame pipeline: an eye pass reads rasterised first hits this frame did not make");
    p.gather.primary = m.primaryHits(pass.eye);
  }
  if (p.foveated())
    m.eyePass.renderFoveated(m.deviceScene, m.map(), p, m.uploadMask(*p.mask), m.stream, *m.clock);
  else
    m.eyePass.render(m.deviceScene, m.map(), p, m.stream, *m.clock);
}

float CudaFrameBackend::inverseDepthAt(Eye eye, size_t pixel) {
  Impl& m = *impl_;
  float value = 0;  // one value, waited for
  PVR_CUDA_CHECK(cudaMemcpyAsync(&value, m.eyePass.inverseDepth(eye) + pixel, sizeof(float), cudaMemcpyDeviceToHost, m.stream));
  PVR_CUDA_CHECK(cudaStreamSynchronize(m.stream));
  return value;
}

void CudaFrameBackend::denoise(const EyePass& pass, const DenoiseParams& params) {
  Impl& m = *impl_;
  const Eye eye = pass.eye;
  DenoiseInputs in;
  in.image = m.eyePass.image(eye);
  in.inverseDepth = m.eyePass.inverseDepth(eye);
  if (pass.foveated()) {
    in.sampleSpacing = m.eyePass.sampleSpacing(eye);
  } else {
    in.emitted = m.eyePass.emitted(eye), in.direct = m.eyePass.direct(eye);
    in.albedo = m.eyePass.albedo(eye), in.normal = m.eyePass.normal(eye);
    in.keepLevels = pass.role == StereoRole::Source;
    if (pass.role == StereoRole::Reuser) {
      in.reusedFrom = m.eyePass.reusedFrom();
      in.sourceNormal = m.eyePass.normal(Eye::Left);
      in.sourceDenoised = m.denoiser.image(Eye::Left);
    }
  }
  m.denoiser.denoise(eye, pass.camera, params, in, pass.stillFrames, m.stream);
}

void CudaFrameBackend::resolveTemporal(const TemporalPass& pass) {
  Impl& m = *impl_;
  m.frame.temporal = true;
  TaaEmitted emission;
  if (pass.emittedApart) {
    emission.emitted = m.eyePass.emitted(pass.eye);
    if (pass.reuser) emission.reusedFrom = m.eyePass.reusedFrom(), emission.sourceEmitted = m.eyePass.emitted(Eye::Left);
  }
  m.temporal.resolve(pass.eye, pass.camera, pass.params, pass.denoised ? m.denoiser.image(pass.eye) : m.eyePass.image(pass.eye),
                     m.eyePass.inverseDepth(pass.eye), pass.foveated ? m.eyePass.sampleSpacing(pass.eye) : nullptr,
                     emission, m.stream);
}

void CudaFrameBackend::forgetHistory(Eye eye) { impl_->temporal.forget(eye); }
void CudaFrameBackend::forgetDenoiseHistory(Eye eye) { impl_->denoiser.forget(eye); }

FrameCounters CudaFrameBackend::finishFrame() {
  Impl& m = *impl_;
  uint32_t shadedVertices[2] = {0, 0};
  unsigned historyPixels[2] = {0, 0}, reused = 0;
  if (m.frame.foveated[0] || m.frame.foveated[1]) m.eyePass.downloadShadedVertices(shadedVertices, m.stream);
  if (m.frame.temporal) m.temporal.downloadHistoryPixels(historyPixels, m.stream);
  if (m.frame.reused) m.eyePass.downloadReusedCount(&reused, m.stream);
  if (m.frame.cached) m.surfaceCache.downloadCounters(m.stream);
  if (m.frame.rasterised) {  // the next pre-pass may overwrite the G-buffer once the reads are done
    m.raster.readersDone->signal(m.stream);
    m.raster.readersSignalled = true;
  }
  PVR_CUDA_CHECK(cudaStreamSynchronize(m.stream));  // also surfaces the frame's faults, if any
  double rasterDrawMs = 0.0;
  if (m.frame.rasterised) m.clock->add(Stage::Primary, kWholeFrame, m.raster.pass->lastGpuMs(&rasterDrawMs));
  FrameCounters c;
  if (m.frame.cached) c.cacheCells = m.surfaceCache.cells(), c.cacheUnplaced = m.surfaceCache.unplacedPoints();
  for (int e = 0; e < 2; ++e) {
    if (!m.frame.rendered[e]) continue;
    c.shadedSamples[e] = m.frame.foveated[e] ? shadedVertices[e] : m.frame.pixels[e];
    c.historyPixels[e] = historyPixels[e];
  }
  c.reusedSamples = reused;
  c.primaryDrawMs = rasterDrawMs;
  c.deviceBytes = cuda::deviceBytesInUse();
  return c;
}

void CudaFrameBackend::readEye(Eye eye, const EyeReadback& what, EyeResult& out) {
  Impl& m = *impl_;
  const size_t pixels = m.frame.pixels[int(eye)];
  auto download = [&](auto* host, const auto* device, size_t n) {
    PVR_CUDA_CHECK(cudaMemcpyAsync(host, device, n * sizeof(*host), cudaMemcpyDeviceToHost, m.stream));
  };
  out.image = Image(m.frame.width[int(eye)], m.frame.height[int(eye)]);
  download(out.image.pixels.data(), deviceImage(eye, what.image), pixels);
  out.inverseDepth.resize(pixels);
  download(out.inverseDepth.data(), m.eyePass.inverseDepth(eye), pixels);
  if (what.sampleSpacing) {
    out.sampleSpacing.emplace(pixels);
    download(out.sampleSpacing->data(), m.eyePass.sampleSpacing(eye), pixels);
  }
  if (what.firstPrim) {
    out.firstPrim.emplace(pixels);
    download(out.firstPrim->data(), m.eyePass.firstPrim(eye), pixels);
  }
  if (what.reusedFrom) {
    out.reusedFrom.emplace(pixels);
    download(out.reusedFrom->data(), m.eyePass.reusedFrom(), pixels);
  }
  PVR_CUDA_CHECK(cudaStreamSynchronize(m.stream));
}

const Vec3* CudaFrameBackend::deviceImage(Eye eye, EyeImage which) const {
  switch (which) {
    case EyeImage::Displayed: return impl_->temporal.image(eye);
    case EyeImage::Denoised: return impl_->denoiser.image(eye);
    case EyeImage::Rendered: break;
  }
  return impl_->eyePass.image(eye);
}

const Vec3* CudaFrameBackend::deviceDirect(Eye eye) const { return impl_->eyePass.direct(eye); }

std::vector<Photon> CudaFrameBackend::mapPhotonsToHost() {
  Impl& m = *impl_;
  std::vector<Photon> photons(m.mapPhotonCount());
  if (!photons.empty())
    PVR_CUDA_CHECK(cudaMemcpyAsync(photons.data(), m.mapPhotons(), photons.size() * sizeof(Photon),
                                   cudaMemcpyDeviceToHost, m.stream));
  PVR_CUDA_CHECK(cudaStreamSynchronize(m.stream));
  return photons;
}

GatherPoint CudaFrameBackend::gatherPointToHost(size_t pixel) {
  Impl& m = *impl_;
  const cuda::DeviceGatherPoints& points = m.eyePass.gatherPoints();
  if (pixel >= points.lobe.capacity()) throw Error("gather point " + std::to_string(pixel) + " is past the eye pass's store");
  float4 planes[cuda::kGatherPointPlanes];
  cuda::GatherPointLobe lobe{};
  for (int k = 0; k < cuda::kGatherPointPlanes; ++k)
    PVR_CUDA_CHECK(cudaMemcpyAsync(&planes[k], points.planes[k].data() + pixel, sizeof(float4), cudaMemcpyDeviceToHost, m.stream));
  PVR_CUDA_CHECK(cudaMemcpyAsync(&lobe, points.lobe.data() + pixel, sizeof lobe, cudaMemcpyDeviceToHost, m.stream));
  PVR_CUDA_CHECK(cudaStreamSynchronize(m.stream));
  // GatherPointStore's layout, read on the host.
  auto xyz = [](float4 v) { return Vec3{v.x, v.y, v.z}; };
  GatherPoint p;
  p.radiance = xyz(planes[cuda::kPlaneRadiance]), p.weight = xyz(planes[cuda::kPlaneWeight]);
  p.position = xyz(planes[cuda::kPlanePosition]), p.normal = xyz(planes[cuda::kPlaneNormal]);
  std::memcpy(&p.lobes, &planes[cuda::kPlaneRadiance].w, sizeof p.lobes);
  p.wall = {planes[cuda::kPlaneWeight].w, planes[cuda::kPlanePosition].w, planes[cuda::kPlaneNormal].w};
  if (p.lobes) p.wo = lobe.wo, p.bsdf = lobe.bsdf;
  return p;
}

const float* CudaFrameBackend::deviceInverseDepth(Eye eye) const { return impl_->eyePass.inverseDepth(eye); }
void* CudaFrameBackend::deviceStream() const { return impl_->stream; }

void CudaFrameBackend::setPhotonPassBvh(PhotonPassBvh bvh, const WideBvh* built) {
  Impl& m = *impl_;
  if (bvh == PhotonPassBvh::Wide && !m.wide.uploaded && m.scene.triangleCount() > 0) {
    // On the frame's stream: ordered before its photon pass (a non-blocking stream does not wait
    // for the default one).
    if (built) m.wide.upload(*built, m.deviceScene.intersector.alphaScene, m.stream);
    else m.wide.upload(WideBvh::build(m.scene), m.deviceScene.intersector.alphaScene, m.stream);
  }
  m.wideInUse = bvh == PhotonPassBvh::Wide;
}

std::vector<Photon> CudaFrameBackend::tracePhotonsToHost(const PhotonTraceParams& params) {
  Impl& m = *impl_;
  uint32_t n = m.tracePhotons(params);
  std::vector<Photon> photons(n);
  if (n)
    PVR_CUDA_CHECK(cudaMemcpyAsync(photons.data(), m.tracer.photons(), n * sizeof(Photon), cudaMemcpyDeviceToHost, m.stream));
  PVR_CUDA_CHECK(cudaStreamSynchronize(m.stream));
  return photons;
}

namespace {
// The median of `repeats` timed runs of `build` (CUDA events), after one untimed run.
template <class Build>
double medianBuildMs(cuda::EventTimer& timer, cudaStream_t stream, int repeats, const Build& build) {
  std::vector<double> times;
  for (int r = -1; r < std::max(repeats, 1); ++r) {
    timer.start(stream);
    build();
    timer.stop(stream);
    const double ms = timer.ms();
    if (r >= 0) times.push_back(ms);
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}
}  // namespace

double CudaFrameBackend::buildHashGrid(const std::vector<Photon>& photons, float radius, int repeats,
                                       GpuHashGridCopy* copy) {
  Impl& m = *impl_;
  cuda::DeviceBuffer<Photon> input;
  input.upload(photons.data(), photons.size(), "benchmark photons", m.stream);
  Bounds3 bounds;  // what the tracer's kernel reduces on the device
  for (const Photon& p : photons) bounds.extend(p.position);
  const double ms = medianBuildMs(m.benchTimer, m.stream, repeats, [&] {
    m.grid.build(input.data(), uint32_t(photons.size()), bounds, radius, m.stream);
  });
  if (copy) m.grid.download(copy->photons, copy->cellStart, copy->sortedToInput);
  m.gridView = m.grid.view();
  return ms;
}

double CudaFrameBackend::buildKdTree(const std::vector<Photon>& photons, int repeats, GpuKdTreeCopy* copy) {
  Impl& m = *impl_;
  cuda::DeviceBuffer<Photon> input;
  input.upload(photons.data(), photons.size(), "benchmark photons", m.stream);
  const double ms = medianBuildMs(m.benchTimer, m.stream, repeats,
                                  [&] { m.tree.build(input.data(), uint32_t(photons.size()), m.stream); });
  if (copy) m.tree.download(copy->photons, copy->axes, copy->nodeToInput);
  m.treeView = m.tree.view();
  return ms;
}

FrameRenderer makeCudaFrameRenderer(const Scene& scene) {
  return FrameRenderer(std::make_unique<CudaFrameBackend>(scene), scene.materials());
}

size_t cudaDeviceMemoryUsedBytes() {
  size_t freeBytes = 0, total = 0;
  if (cudaMemGetInfo(&freeBytes, &total) != cudaSuccess) {
    cudaGetLastError();
    return 0;
  }
  return total - freeBytes;
}

}  // namespace pvr
