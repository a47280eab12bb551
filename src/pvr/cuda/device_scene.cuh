#pragma once
// The scene and its BVH on the GPU, for the shared algorithm code's device side.
#include "pvr/accel/bvh_traversal.h"
#include "pvr/cuda/cuda_util.cuh"
#include "pvr/photon/hash_grid.h"
#include "pvr/photon/kd_tree.h"
#include "pvr/photon/photon_trace.h"
#include "pvr/scene/scene.h"

namespace pvr::cuda {

// The renderer's ray queries: the binary BVH. The 8-wide quantized BVH (wide_bvh.h) traces 2-3x
// faster in standalone ray kernels (bench --suite rays) but made the eye kernels slower on the
// H200, inlined or not (docs/benchmarks.md, 2026-12-05), so it is not used here yet. Those
// figures predate the binary traversal's local-memory fix (529141c): to be measured again.
using SceneIntersector = BvhIntersector;

struct DeviceScene {
  DeviceBuffer<Vec3> vertices, normals, faceNormals;
  DeviceBuffer<Vec2> uvs[2];
  DeviceBuffer<uint32_t> texels;         ///< every texture's levels, one after the other
  DeviceBuffer<TextureView> textures;    ///< pointing into `texels`
  DeviceBuffer<uint32_t> indices, materialIds, lightTriangles;
  DeviceBuffer<Material> materials;
  DeviceBuffer<PunctualLight> punctualLights;
  DeviceBuffer<float> lightCdf;
  DeviceBuffer<BvhNode> nodes;
  DeviceBuffer<BvhTriangle> triangles;
  SceneView view;
  DeviceBuffer<SceneView> viewOnDevice;  ///< `view` in device memory: the intersectors' alpha masks read it
  SceneIntersector intersector;

  void upload(const Scene& scene, const Bvh& bvh);
};

}  // namespace pvr::cuda
