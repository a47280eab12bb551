#pragma once
// An 8-wide BVH in device memory and the intersector over it: the photon pass's (when asked) and
// the rays benchmark's, uploaded one way.
#include "pvr/accel/wide_bvh.h"
#include "pvr/accel/wide_bvh_traversal.h"
#include "pvr/cuda/cuda_util.cuh"

namespace pvr::cuda {

struct DeviceWideBvh {
  DeviceBuffer<WideBvhNode> nodes;
  DeviceBuffer<BvhTriangle> triangles;
  WideBvhIntersector intersector;
  bool uploaded = false;

  // Uploads `bvh` on `stream` and waits for it (the caller may drop `bvh` on return); hits on
  // texels `alphaScene`'s materials cut out are skipped (null: none).
  void upload(const WideBvh& bvh, const SceneView* alphaScene, cudaStream_t stream);
};

}  // namespace pvr::cuda
