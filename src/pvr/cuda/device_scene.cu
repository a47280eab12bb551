#include "pvr/cuda/device_scene.cuh"

#include <algorithm>
#include <vector>

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
  lightTriangles.upload(host.lightTriangles, host.triangleLightCount, "light triangles");
  lightCdf.upload(host.lightCdf, size_t(host.lightCount) + 1, "light CDF");
  if (host.punctualCount) punctualLights.upload(host.punctualLights, host.punctualCount, "punctual lights");
  for (int set = 0; set < 2; ++set)
    if (host.uvs[set]) uvs[set].upload(host.uvs[set], vertexCount, "texture coordinates");
  // Textures: one texel buffer; the views' pointers rebased onto it.
  std::vector<TextureView> deviceTextures(scene.textureViews());
  size_t texelCount = 0;
  for (uint32_t t = 0; t < scene.textureCount(); ++t) texelCount += scene.textureTexels(t).size();
  texels.reserve(std::max<size_t>(texelCount, 1), "textures");
  size_t offset = 0;
  for (uint32_t t = 0; t < scene.textureCount(); ++t) {
    const std::vector<uint32_t>& level = scene.textureTexels(t);
    PVR_CUDA_CHECK(cudaMemcpy(texels.data() + offset, level.data(), level.size() * sizeof(uint32_t), cudaMemcpyHostToDevice));
    deviceTextures[t].texels = texels.data() + offset;
    offset += level.size();
  }
  if (!deviceTextures.empty()) textures.upload(deviceTextures.data(), deviceTextures.size(), "texture views");
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
  view.punctualLights = host.punctualCount ? punctualLights.data() : nullptr;
  for (int set = 0; set < 2; ++set) view.uvs[set] = host.uvs[set] ? uvs[set].data() : nullptr;
  view.textures = deviceTextures.empty() ? nullptr : textures.data();
  viewOnDevice.upload(&view, 1, "scene view");
  intersector.alphaScene = scene.hasAlphaTestedMaterial() ? viewOnDevice.data() : nullptr;
  intersector.bvh = {nodes.data(), triangles.data(), uint32_t(bvh.nodes().size()), uint32_t(bvh.triangles().size())};
}

}  // namespace pvr::cuda
