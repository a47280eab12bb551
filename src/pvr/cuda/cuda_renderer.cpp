#include "pvr/cuda/cuda_renderer.h"

#include <algorithm>

#include "pvr/cuda/gpu_gather.cuh"
#include "pvr/cuda/gpu_scene.cuh"
#include "pvr/cuda/gpu_temporal.cuh"
#include "pvr/foveation/mask.h"

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

struct CudaFrameRenderer::Impl {
  const Scene& scene;
  Bvh bvh;
  cudaStream_t stream = nullptr;
  cuda::DeviceScene deviceScene;
  cuda::GpuPhotonTracer tracer;
  cuda::GpuHashGrid grid;
  cuda::GpuKdTree tree;
  cuda::GpuGather gather;
  cuda::GpuTemporal temporal;
  cuda::EventTimer traceTimer, buildTimer, scatterTimer, reconstructTimer[2], temporalTimer[2];
  // The foveation mask last used, uploaded once and keyed on its content id.
  uint64_t maskId = 0;
  uint32_t maskVertices = 0, maskTriangleCount = 0;
  cuda::DeviceBuffer<MaskPoint> maskOffsets;
  cuda::DeviceBuffer<uint32_t> maskTriangles, maskTrianglesBySize;
  uint32_t smallTriangles = 0;

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
  cuda::EyeTimers eyeTimers[2];
  cudaDeviceProp properties{};

  explicit Impl(const Scene& s) : scene(s), bvh(Bvh::build(s)) {
    PVR_CUDA_CHECK(cudaGetDeviceProperties(&properties, 0));
    PVR_CUDA_CHECK(cudaStreamCreateWithFlags(&stream, cudaStreamNonBlocking));
    deviceScene.upload(scene, bvh);
  }
  ~Impl() { cudaStreamDestroy(stream); }
};

CudaFrameRenderer::CudaFrameRenderer(const Scene& scene) {
  std::string why;
  if (!cudaDeviceUsable(&why)) throw Error("--backend cuda: " + why);
  impl_ = std::make_unique<Impl>(scene);
}

CudaFrameRenderer::~CudaFrameRenderer() = default;

std::string CudaFrameRenderer::deviceName() const {
  const cudaDeviceProp& p = impl_->properties;
  return std::string(p.name) + " (sm_" + std::to_string(p.major) + std::to_string(p.minor) + ", " +
         std::to_string(p.multiProcessorCount) + " SMs, " + std::to_string(p.totalGlobalMem >> 30) + " GiB)";
}

const BvhBuildStats& CudaFrameRenderer::bvhStats() const { return impl_->bvh.stats(); }

size_t CudaFrameRenderer::deviceBytes() const { return cuda::deviceBytesInUse(); }

FrameResult CudaFrameRenderer::render(const StereoRig& rig, const RenderOptions& options, bool images) {
  validateOptions(options, rig);
  Impl& m = *impl_;
  cuda::DeviceMaskView mask;
  if (options.foveation.mask) {
    checkMaskFits(*options.foveation.mask, rig.width, rig.height);
    mask = m.uploadMask(*options.foveation.mask);
  }
  FrameResult frame;
  PhotonTraceParams traceParams = options.photonTraceParams();

  m.traceTimer.start(m.stream);
  uint32_t stored = m.tracer.trace(m.deviceScene, traceParams, m.stream);
  m.traceTimer.stop(m.stream);
  frame.storedPhotons = stored;

  cuda::DeviceMap map;
  HashGridView gridView;
  KdTreeView treeView;
  double kdMs = 0;
  if (options.map == PhotonMapKind::HashGrid) {
    m.buildTimer.start(m.stream);
    m.grid.build(m.tracer.photons(), stored, m.tracer.bounds(), options.gather.density.radius, m.stream);
    m.buildTimer.stop(m.stream);
    gridView = m.grid.view();
    map.grid = &gridView;
    frame.mapBytes = m.grid.memoryBytes();
  } else {
    cuda::GpuKdTree::Timing t = m.tree.build(m.tracer.photons(), stored, m.stream);
    kdMs = t.downloadMs + t.buildMs + t.uploadMs;  // host clock: the build is on the host
    treeView = m.tree.view();
    map.tree = &treeView;
    frame.mapBytes = m.tree.memoryBytes();
  }

  unsigned reused = 0;
  RenderOptions eyeOptions = options;  // foveated: the right eye's gaze may follow the left's
  for (int e = 0; e < 2; ++e) {  // the left eye first: the right eye may reuse it
    if (!options.eyes[e]) {
      m.temporal.forget(Eye(e));  // its history would be stale when it comes back
      continue;
    }
    if (e == 1 && options.stereo == StereoMode::Scatter) {
      m.scatterTimer.start(m.stream);
      m.gather.scatter(m.deviceScene, rig, m.stream);
      m.scatterTimer.stop(m.stream);
    }
    if (options.foveation.mask) {
      FoveationOptions& foveation = eyeOptions.foveation;
      if (e == 1 && foveation.verge) {
        float leftInverseDepth = 0;
        if (options.eyes[0]) {  // the left eye's depth at its gaze: one value, waited for
          PVR_CUDA_CHECK(cudaMemcpyAsync(&leftInverseDepth,
                                         m.gather.inverseDepth(Eye::Left) + foveation.gazePixelIndex(0, rig.width, rig.height),
                                         sizeof(float), cudaMemcpyDeviceToHost, m.stream));
          PVR_CUDA_CHECK(cudaStreamSynchronize(m.stream));
        }
        vergeRightGaze(rig, foveation, options.eyes[0] ? &leftInverseDepth : nullptr);
      }
      std::copy(foveation.gaze[e], foveation.gaze[e] + 2, frame.gaze[e]);
      m.gather.renderFoveatedEye(m.deviceScene, map, eyeOptions, rig, Eye(e), mask, m.stream, m.eyeTimers[e],
                                 m.reconstructTimer[e]);
    } else {
      m.gather.renderEye(m.deviceScene, map, options, rig, Eye(e), m.stream, m.eyeTimers[e]);
    }
    if (!options.temporal.enabled) {
      m.temporal.forget(Eye(e));
      continue;
    }
    m.temporalTimer[e].start(m.stream);
    m.temporal.resolve(Eye(e), rig.eye(Eye(e)), options.temporal.taa, m.gather.image(Eye(e)),
                       m.gather.inverseDepth(Eye(e)), options.foveation.mask ? m.gather.sampleSpacing(Eye(e)) : nullptr,
                       m.stream);
    m.temporalTimer[e].stop(m.stream);
  }
  uint32_t shadedVertices[2] = {0, 0};
  unsigned historyPixels[2] = {0, 0};
  if (options.foveation.mask) m.gather.downloadShadedVertices(shadedVertices, m.stream);
  if (options.temporal.enabled) m.temporal.downloadHistoryPixels(historyPixels, m.stream);
  if (options.stereo != StereoMode::Separate) m.gather.downloadReusedCount(&reused, m.stream);
  PVR_CUDA_CHECK(cudaStreamSynchronize(m.stream));
  frame.reusedPixels = reused;
  if (options.stereo == StereoMode::Scatter) frame.timings.scatterMs = m.scatterTimer.ms();
  frame.timings.photonTraceMs = m.traceTimer.ms();
  frame.timings.mapBuildMs = options.map == PhotonMapKind::HashGrid ? m.buildTimer.ms() : kdMs;
  for (int e = 0; e < 2; ++e) {
    if (!options.eyes[e]) continue;
    frame.timings.eyeRayMs[e] = m.eyeTimers[e].raysMs();
    frame.timings.densityMs[e] = m.eyeTimers[e].densityMs();
    frame.timings.eyeMs[e] = frame.timings.eyeRayMs[e] + frame.timings.densityMs[e];
    frame.shadedSamples[e] = size_t(rig.width) * rig.height;
    if (options.foveation.mask) {
      frame.timings.reconstructMs[e] = m.reconstructTimer[e].ms();
      frame.timings.eyeMs[e] += frame.timings.reconstructMs[e];
      frame.shadedSamples[e] = shadedVertices[e];
    }
    if (options.temporal.enabled) {
      frame.timings.temporalMs[e] = m.temporalTimer[e].ms();
      frame.timings.eyeMs[e] += frame.timings.temporalMs[e];
      frame.historyPixels[e] = historyPixels[e];
    }
  }
  frame.timings.eyeMs[1] += frame.timings.scatterMs;
  frame.deviceBytes = cuda::deviceBytesInUse();

  if (images) {
    for (int e = 0; e < 2; ++e) {
      if (!options.eyes[e]) continue;
      EyeResult& out = frame.eyes[e];
      const size_t pixels = size_t(rig.width) * rig.height;
      out.image = Image(rig.width, rig.height);
      const Vec3* shown = options.temporal.enabled ? m.temporal.image(Eye(e)) : m.gather.image(Eye(e));
      PVR_CUDA_CHECK(cudaMemcpyAsync(out.image.pixels.data(), shown, pixels * sizeof(Vec3), cudaMemcpyDeviceToHost, m.stream));
      out.inverseDepth.resize(pixels);
      PVR_CUDA_CHECK(cudaMemcpyAsync(out.inverseDepth.data(), m.gather.inverseDepth(Eye(e)), pixels * sizeof(float),
                                     cudaMemcpyDeviceToHost, m.stream));
      if (options.foveation.mask) {
        out.sampleSpacing.resize(pixels);
        PVR_CUDA_CHECK(cudaMemcpyAsync(out.sampleSpacing.data(), m.gather.sampleSpacing(Eye(e)), pixels * sizeof(float),
                                       cudaMemcpyDeviceToHost, m.stream));
      } else {
        out.firstPrim.resize(pixels);
        PVR_CUDA_CHECK(cudaMemcpyAsync(out.firstPrim.data(), m.gather.firstPrim(Eye(e)), pixels * sizeof(uint32_t),
                                       cudaMemcpyDeviceToHost, m.stream));
      }
      if (e == 1 && options.stereo != StereoMode::Separate && !options.foveation.mask) {
        out.reusedFrom.resize(pixels);
        PVR_CUDA_CHECK(cudaMemcpyAsync(out.reusedFrom.data(), m.gather.reusedFrom(), out.reusedFrom.size() * sizeof(uint32_t),
                                       cudaMemcpyDeviceToHost, m.stream));
      }
    }
    PVR_CUDA_CHECK(cudaStreamSynchronize(m.stream));
  }
  return frame;
}

void CudaFrameRenderer::resetHistory() {
  for (Eye e : {Eye::Left, Eye::Right}) impl_->temporal.forget(e);
}

std::vector<Photon> CudaFrameRenderer::tracePhotons(const PhotonTraceParams& params) {
  Impl& m = *impl_;
  uint32_t n = m.tracer.trace(m.deviceScene, params, m.stream);
  std::vector<Photon> photons(n);
  if (n)
    PVR_CUDA_CHECK(cudaMemcpyAsync(photons.data(), m.tracer.photons(), n * sizeof(Photon), cudaMemcpyDeviceToHost, m.stream));
  PVR_CUDA_CHECK(cudaStreamSynchronize(m.stream));
  return photons;
}

double CudaFrameRenderer::buildHashGrid(const std::vector<Photon>& photons, float radius, int repeats,
                                        GpuHashGridCopy* copy) {
  Impl& m = *impl_;
  cuda::DeviceBuffer<Photon> input;
  input.upload(photons.data(), photons.size(), "benchmark photons", m.stream);
  Bounds3 bounds;  // what the tracer's kernel reduces on the device
  for (const Photon& p : photons) bounds.extend(p.position);
  std::vector<double> times;
  for (int r = -1; r < std::max(repeats, 1); ++r) {
    m.buildTimer.start(m.stream);
    m.grid.build(input.data(), uint32_t(photons.size()), bounds, radius, m.stream);
    m.buildTimer.stop(m.stream);
    double ms = m.buildTimer.ms();
    if (r >= 0) times.push_back(ms);
  }
  if (copy) m.grid.download(copy->photons, copy->cellStart, copy->sortedToInput);
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

GpuRayThroughput CudaFrameRenderer::measureRays(const StereoRig& rig, int repeats) {
  cuda::RayThroughput t = cuda::measureRayThroughput(impl_->deviceScene, rig, repeats, impl_->stream);
  GpuRayThroughput out;
  out.primaryRays = t.primaryRays, out.shadowRays = t.shadowRays, out.diffuseRays = t.diffuseRays;
  out.primaryMs = t.primaryMs, out.shadowMs = t.shadowMs, out.diffuseMs = t.diffuseMs;
  out.leftPrimaryHits = std::move(t.primaryHits);
  return out;
}

}  // namespace pvr
