#include "pvr/cuda/eye_kernels.cuh"

namespace pvr::cuda {
namespace {

// Scatter: each left pixel's reusable surface, if the right eye sees it, lands on one right pixel;
// the nearest one per pixel wins.
__global__ void scatterKernel(SceneView scene, SceneIntersector sceneIntersector, const SurfaceRecord* surfaces,
                              int sourceWidth, int sourceHeight, EyeCamera target, unsigned long long* scattered) {
  const SceneIntersector intersector = withSharedStack<kTile * kTile>(sceneIntersector);
  int x, y;
  if (!tilePixel(sourceWidth, sourceHeight, x, y)) return;
  uint32_t source = uint32_t(y) * uint32_t(sourceWidth) + uint32_t(x);
  uint32_t pixel;
  uint64_t entry;
  if (scatterTarget(scene, intersector, surfaces[source], source, target, pixel, entry))
    atomicMin(scattered + pixel, static_cast<unsigned long long>(entry));
}


}  // namespace

void GpuEyePass::scatter(const DeviceScene& scene, const EyeCamera& target, cudaStream_t stream) {
  const size_t pixels = size_t(target.width) * target.height;
  scattered_.reserve(pixels, "scatter buffer");
  PVR_CUDA_CHECK(cudaMemsetAsync(scattered_.data(), 0xff, pixels * sizeof(uint64_t), stream));  // kNothingScattered
  // The source eye has the target's size (both eyes of a rig share it).
  launch("stereo scatter", scatterKernel, tileGrid(target.width, target.height), dim3(kTile, kTile), 0, stream,
         scene.view, scene.intersector, surfaces_.data(), target.width, target.height, target,
         reinterpret_cast<unsigned long long*>(scattered_.data()));
}

}  // namespace pvr::cuda
