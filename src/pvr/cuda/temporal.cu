#include "pvr/cuda/temporal.cuh"

namespace pvr::cuda {
namespace {

constexpr int kBlock = 16;

// One thread per pixel; the pixels that took history are counted per warp.
// `displayed` (null: the history is what is displayed) receives the history plus the emitted part.
__global__ void resolveKernel(TaaView view, Vec3* history, Vec3* displayed, unsigned* historyPixels) {
  int x = int(blockIdx.x) * kBlock + int(threadIdx.x), y = int(blockIdx.y) * kBlock + int(threadIdx.y);
  bool usedHistory = false;
  if (x < view.camera.width && y < view.camera.height) {
    const TaaPixel p = resolveTemporalPixel(view, x, y);
    const size_t pixel = size_t(y) * view.camera.width + x;
    history[pixel] = p.history;
    if (displayed) displayed[pixel] = p.displayed;
    usedHistory = p.usedHistory;
  }
  countInWarp(historyPixels, usedHistory);
}

}  // namespace

void GpuTemporal::resolve(Eye eye, const EyeCamera& camera, const TaaParams& params, const Vec3* current,
                          const float* inverseDepth, const float* sampleSpacing, const TaaEmitted& emission,
                          cudaStream_t stream) {
  const int e = int(eye);
  const size_t pixels = size_t(camera.width) * camera.height;
  const int from = latest_[e], to = 1 - from;
  const bool history = valid_[e] && camera_[e].width == camera.width && camera_[e].height == camera.height;
  colour_[e][to].reserve(pixels, "TAA history");
  depth_[e].reserve(pixels, "TAA history depth");
  emittedApart_[e] = emission.emitted != nullptr;
  if (emittedApart_[e]) displayed_[e].reserve(pixels, "TAA displayed image");
  historyPixels_.reserve(2, "TAA history count");
  TaaView view;
  view.camera = camera;
  view.previousCamera = camera_[e];
  view.current = current;
  view.inverseDepth = inverseDepth;
  view.sampleSpacing = sampleSpacing;
  view.history = history ? colour_[e][from].data() : nullptr;
  view.historyInverseDepth = history ? depth_[e].data() : nullptr;
  view.emission = emission;
  view.params = params;
  PVR_CUDA_CHECK(cudaMemsetAsync(historyPixels_.data() + e, 0, sizeof(unsigned), stream));
  dim3 grid(unsigned((camera.width + kBlock - 1) / kBlock), unsigned((camera.height + kBlock - 1) / kBlock));
  launch("temporal resolve", resolveKernel, grid, dim3(kBlock, kBlock), 0, stream, view, colour_[e][to].data(),
         emittedApart_[e] ? displayed_[e].data() : nullptr, historyPixels_.data() + e);
  PVR_CUDA_CHECK(cudaMemcpyAsync(depth_[e].data(), inverseDepth, pixels * sizeof(float), cudaMemcpyDeviceToDevice, stream));
  latest_[e] = to;
  camera_[e] = camera;
  valid_[e] = true;
}

void GpuTemporal::downloadHistoryPixels(unsigned host[2], cudaStream_t stream) const {
  host[0] = host[1] = 0;
  if (historyPixels_.data())
    PVR_CUDA_CHECK(cudaMemcpyAsync(host, historyPixels_.data(), 2 * sizeof(unsigned), cudaMemcpyDeviceToHost, stream));
}

size_t GpuTemporal::memoryBytes() const {
  size_t bytes = historyPixels_.bytes();
  for (int e = 0; e < 2; ++e)
    bytes += colour_[e][0].bytes() + colour_[e][1].bytes() + displayed_[e].bytes() + depth_[e].bytes();
  return bytes;
}

}  // namespace pvr::cuda
