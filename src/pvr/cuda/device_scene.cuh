#pragma once
// The scene and its BVH on the GPU, for the shared algorithm code's device side.
#include "pvr/accel/wide_bvh_traversal.h"
#include "pvr/cuda/cuda_util.cuh"
#include "pvr/photon/hash_grid.h"
#include "pvr/photon/kd_tree.h"
#include "pvr/photon/photon_trace.h"
#include "pvr/scene/scene.h"

namespace pvr::cuda {

// The renderer's ray queries: the 8-wide quantized BVH (wide_bvh.h).
using SceneIntersector = WideBvhIntersector;

struct DeviceScene {
  DeviceBuffer<Vec3> vertices, normals, faceNormals;
  DeviceBuffer<Vec2> uvs[2];
  DeviceBuffer<uint32_t> texels;         ///< every texture's levels, one after the other
  DeviceBuffer<TextureView> textures;    ///< pointing into `texels`
  DeviceBuffer<uint32_t> indices, materialIds, lightTriangles;
  DeviceBuffer<Material> materials;
  DeviceBuffer<PunctualLight> punctualLights;
  DeviceBuffer<float> lightCdf;
  DeviceBuffer<WideBvhNode> nodes;
  DeviceBuffer<BvhTriangle> triangles;
  SceneView view;
  SceneIntersector intersector;

  void upload(const Scene& scene, const WideBvh& bvh);
};

}  // namespace pvr::cuda
