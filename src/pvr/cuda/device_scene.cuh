#pragma once
// The scene and its BVH on the GPU, for the shared algorithm code's device side.
#include "pvr/accel/bvh_traversal.h"
#include "pvr/cuda/cuda_util.cuh"
#include "pvr/photon/hash_grid.h"
#include "pvr/photon/kd_tree.h"
#include "pvr/photon/photon_trace.h"
#include "pvr/scene/scene.h"

namespace pvr::cuda {

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
  BvhIntersector intersector;

  void upload(const Scene& scene, const Bvh& bvh);
};

}  // namespace pvr::cuda
