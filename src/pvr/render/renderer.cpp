#include "pvr/render/renderer.h"

#include <cstdio>

#include "pvr/cpu/cpu_frame_backend.h"
#include "pvr/util/error.h"
#ifdef PVR_HAVE_CUDA
#include "pvr/cuda/cuda_frame_backend.h"
#include "pvr/cuda/image_checks.h"
#endif

namespace pvr {

BackendKind parseBackendKind(const std::string& text) {
  if (text == "cpu") return BackendKind::Cpu;
  if (text == "cuda") return BackendKind::Cuda;
  if (text == "auto") return BackendKind::Auto;
  throw Error("--backend must be cpu, cuda or auto, got '" + text + "'");
}

bool cudaBackendAvailable(std::string* why) {
#ifdef PVR_HAVE_CUDA
  return cudaDeviceUsable(why);
#else
  if (why) *why = "this build of photonvr has no CUDA backend (nvcc was not found when it was built)";
  return false;
#endif
}

std::unique_ptr<FrameBackend> makeFrameBackend(BackendKind kind, const Scene& scene) {
  std::string why;
  if (kind == BackendKind::Cpu) return std::make_unique<CpuFrameBackend>(scene);
  bool cuda = cudaBackendAvailable(&why);
  if (kind == BackendKind::Auto && !cuda) return std::make_unique<CpuFrameBackend>(scene);
  if (!cuda) throw Error("--backend cuda: " + why);
#ifdef PVR_HAVE_CUDA
  return std::make_unique<CudaFrameBackend>(scene);
#else
  throw Error("--backend cuda: " + why);
#endif
}

std::unique_ptr<FrameRenderer> makeFrameRenderer(BackendKind kind, const Scene& scene) {
  return std::make_unique<FrameRenderer>(makeFrameBackend(kind, scene), scene.materials());
}

Renderer::Renderer(const Scene& scene, BackendKind backend)
    : rig_(scene.rig), frames_(makeFrameBackend(backend, scene), scene.materials()) {}

size_t gpuMemoryUsedBytes() {
#ifdef PVR_HAVE_CUDA
  return cudaDeviceMemoryUsedBytes();
#else
  return 0;
#endif
}

struct DeviceImageCheck::Impl {
#ifdef PVR_HAVE_CUDA
  cuda::NonFiniteCounter counter;
#endif
};

DeviceImageCheck::DeviceImageCheck() : impl_(std::make_unique<Impl>()) {}
DeviceImageCheck::~DeviceImageCheck() = default;

void DeviceImageCheck::nonFinitePixels(const Renderer& renderer, uint64_t counts[2]) {
  nonFinitePixels(renderer.frameRenderer(), size_t(renderer.rig().width) * size_t(renderer.rig().height),
                  counts);
}

void DeviceImageCheck::nonFinitePixels(const FrameRenderer& frames, size_t pixels, uint64_t counts[2]) {
  const Vec3* images[2] = {frames.deviceImage(Eye::Left), frames.deviceImage(Eye::Right)};
  count(images, pixels, frames.deviceStream(), counts);
}

void DeviceImageCheck::nonFinitePixels(FrameRenderer& frames, size_t pixels, EyeImage which, uint64_t counts[2]) {
  const bool rendered[2] = {frames.deviceImage(Eye::Left) != nullptr, frames.deviceImage(Eye::Right) != nullptr};
  const Vec3* images[2] = {rendered[0] ? frames.backend().deviceImage(Eye::Left, which) : nullptr,
                           rendered[1] ? frames.backend().deviceImage(Eye::Right, which) : nullptr};
  count(images, pixels, frames.deviceStream(), counts);
}

void DeviceImageCheck::count(const Vec3* const images[2], size_t pixels, void* stream, uint64_t counts[2]) {
  counts[0] = counts[1] = 0;
#ifdef PVR_HAVE_CUDA
  if (!images[0] && !images[1]) return;
  impl_->counter.count(images, pixels, stream, counts);
#else
  (void)images, (void)pixels, (void)stream;
#endif
}

std::string describeNonFinitePixels(FrameRenderer& frames, EyeImage shown, bool reusing) {
  std::string out;
  EyeResult rendered[2];
  for (Eye eye : {Eye::Left, Eye::Right}) {
    const int e = int(eye);
    EyeResult seen;
    EyeReadback what;
    what.image = shown;
    frames.backend().readEye(eye, what, seen);
    what.image = EyeImage::Rendered;
    what.reusedFrom = reusing && eye == Eye::Right;
    frames.backend().readEye(eye, what, rendered[e]);
    const EyeResult& r = rendered[e];
    const size_t n = r.image.pixels.size();
    size_t shownBad = 0, renderedBad = 0, reusedBad = 0, first = n;
    for (size_t i = 0; i < n; ++i) {
      shownBad += !isFinite(seen.image.pixels[i]);
      if (isFinite(r.image.pixels[i])) continue;
      ++renderedBad;
      reusedBad += r.reusedFrom && (*r.reusedFrom)[i] != kNotReused;
      if (first == n) first = i;
    }
    const std::vector<Vec3>& image = first < n ? r.image.pixels : seen.image.pixels;
    if (first == n)
      for (size_t i = 0; i < n && first == n; ++i)
        if (!isFinite(seen.image.pixels[i])) first = i;
    char line[480];
    std::snprintf(line, sizeof line, "%seye %d: %zu shown, %zu rendered (%zu reused)", e ? "; " : "", e, shownBad,
                  renderedBad, reusedBad);
    out += line;
    if (first == n) continue;
    const Vec3 c = image[first];
    std::snprintf(line, sizeof line, ", the first %s at (%zu, %zu): (%g, %g, %g), inverse depth %g, ",
                  renderedBad ? "rendered" : "shown", first % size_t(r.image.width), first / size_t(r.image.width), c.x,
                  c.y, c.z, r.inverseDepth[first]);
    out += line;
    const uint32_t source = r.reusedFrom ? (*r.reusedFrom)[first] : kNotReused;
    if (source == kNotReused) {
      out += "shaded by its eye";
    } else {
      const Vec3 left = rendered[0].image.pixels[source];
      std::snprintf(line, sizeof line, "reused left pixel %u (left rendered (%g, %g, %g))", source, left.x, left.y,
                    left.z);
      out += line;
    }
  }
  return out;
}

FrameResult Renderer::renderFrame(const Pose& head, const float gaze[2], FrameOutput output) {
  rig_.head = head;
  RenderOptions o = options_;
  if (gaze) {
    o.foveation.gaze[0][0] = gaze[0], o.foveation.gaze[0][1] = gaze[1];
    o.foveation.verge = true;
  }
  return frames_.render(rig_, o, output == FrameOutput::HostImages);
}

}  // namespace pvr
