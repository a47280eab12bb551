// Compiles the shared algorithm code (photon tracing, both photon maps, density estimation,
// pixel shading) into CUDA kernels, so that CI catches host-only constructs creeping into the
// PVR_HOST_DEVICE headers before the CUDA backend needs them. Built whenever nvcc is present;
// nothing here runs.
#include "pvr/photon/gather.h"
#include "pvr/photon/hash_grid.h"
#include "pvr/photon/kd_tree.h"
#include "pvr/photon/photon_trace.h"

namespace pvr_device_check {

// The Intersector interface with no geometry: the kernels only have to compile.
struct EmptySceneIntersector {
  __device__ bool intersect(const pvr::Ray&, float, pvr::Hit&) const { return false; }
  __device__ bool occluded(const pvr::Ray&, float) const { return false; }
};

template <class Map>
__global__ void shadeKernel(pvr::SceneView scene, Map map, pvr::GatherParams params, pvr::EyeCamera camera,
                            pvr::Vec3* out) {
  int x = blockIdx.x * blockDim.x + threadIdx.x;
  if (x >= camera.width) return;
  out[x] = pvr::shadePixel(scene, EmptySceneIntersector{}, map, params, camera, pvr::Eye::Left, x, 0).radiance;
}

__global__ void traceKernel(pvr::SceneView scene, pvr::PhotonTraceParams params, pvr::Photon* out, int* counts) {
  uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= params.photonCount) return;
  counts[i] = pvr::tracePhoton(scene, EmptySceneIntersector{}, params, i, out + size_t(i) * params.maxDepth);
}


template __global__ void shadeKernel<pvr::HashGridView>(pvr::SceneView, pvr::HashGridView, pvr::GatherParams,
                                                        pvr::EyeCamera, pvr::Vec3*);
template __global__ void shadeKernel<pvr::KdTreeView>(pvr::SceneView, pvr::KdTreeView, pvr::GatherParams,
                                                      pvr::EyeCamera, pvr::Vec3*);

}  // namespace pvr_device_check
