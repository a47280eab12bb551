#include "pvr/cuda/device_wide_bvh.h"

namespace pvr::cuda {

void DeviceWideBvh::upload(const WideBvh& bvh, const SceneView* alphaScene, cudaStream_t stream) {
  if (!bvh.nodes().empty()) nodes.upload(bvh.nodes().data(), bvh.nodes().size(), "wide BVH nodes", stream);
  if (!bvh.triangles().empty()) triangles.upload(bvh.triangles().data(), bvh.triangles().size(), "wide BVH triangles", stream);
  PVR_CUDA_CHECK(cudaStreamSynchronize(stream));  // before the host arrays may go
  intersector.bvh = {nodes.data(), triangles.data(), uint32_t(bvh.nodes().size()), uint32_t(bvh.triangles().size())};
  intersector.alphaScene = alphaScene;
  uploaded = true;
}

}  // namespace pvr::cuda
