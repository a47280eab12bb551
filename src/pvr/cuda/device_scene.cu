#include "pvr/cuda/device_scene.cuh"

namespace pvr::cuda {

void DeviceScene::upload(const Scene& scene, const Bvh& bvh) {
  SceneView host = scene.view();
  size_t vertexCount = scene.vertices().size();
  vertices.upload(scene.vertices().data(), vertexCount, "scene vertices");
  if (host.normals) normals.upload(host.normals, vertexCount, "scene normals");
  faceNormals.upload(scene.faceNormals().data(), scene.faceNormals().size(), "face normals");
  indices.upload(host.indices, 3 * size_t(host.triangleCount), "scene indices");
  materialIds.upload(host.materialIds, host.triangleCount, "material ids");
  materials.upload(scene.materials().data(), scene.materials().size(), "materials");
  lightTriangles.upload(host.lightTriangles, host.lightCount, "light triangles");
  lightCdf.upload(host.lightCdf, size_t(host.lightCount) + 1, "light CDF");
  nodes.upload(bvh.nodes().data(), bvh.nodes().size(), "BVH nodes");
  triangles.upload(bvh.triangles().data(), bvh.triangles().size(), "BVH triangles");
  PVR_CUDA_CHECK(cudaDeviceSynchronize());
  view = host;
  view.vertices = vertices.data();
  view.normals = host.normals ? normals.data() : nullptr;
  view.faceNormals = faceNormals.data();
  view.indices = indices.data();
  view.materialIds = materialIds.data();
  view.materials = materials.data();
  view.lightTriangles = lightTriangles.data();
  view.lightCdf = lightCdf.data();
  intersector.bvh = {nodes.data(), triangles.data(), uint32_t(bvh.nodes().size()), uint32_t(bvh.triangles().size())};
}

}  // namespace pvr::cuda
