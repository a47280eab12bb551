#pragma once
// Scenes built in code for analytic tests.
#include <stdexcept>
#include <string>

#include "pvr/scene/scene.h"

namespace pvr::test {

// A scene's material by name; throws (failing the test) when there is none.
inline const Material& materialNamed(const Scene& s, const std::string& name) {
  for (size_t i = 0; i < s.materials().size(); ++i)
    if (s.materialNames()[i] == name) return s.materials()[i];
  throw std::runtime_error("no material " + name);
}

// Adds an axis-aligned quad of a unit cube [-0.5, 0.5]^3 whose front face (and normal) points
// into the cube: the face at coordinate `side` (-1 or +1) of `axis`.
inline void addInwardFace(Scene& scene, int axis, float side, uint32_t material) {
  int u = (axis + 1) % 3, v = (axis + 2) % 3;
  auto corner = [&](float a, float b) {
    Vec3 p;
    p[axis] = 0.5f * side;
    p[u] = a;
    p[v] = b;
    return p;
  };
  std::vector<Vec3> c = {corner(-0.5f, -0.5f), corner(0.5f, -0.5f), corner(0.5f, 0.5f), corner(-0.5f, 0.5f)};
  Vec3 n = cross(c[1] - c[0], c[2] - c[0]);
  std::vector<uint32_t> idx = n[axis] * side < 0 ? std::vector<uint32_t>{0, 1, 2, 0, 2, 3}
                                                 : std::vector<uint32_t>{0, 2, 1, 0, 3, 2};
  scene.addMesh("face", c, {}, idx, material);
}

// A closed unit cube whose every wall has diffuse albedo rho and emits Le: a white furnace.
// The exact radiance everywhere inside is Le / (1 - rho).
inline Scene furnaceBox(float rho, float le) {
  Scene scene;
  scene.name = "furnace";
  Material m;
  m.albedo = Vec3(rho);
  m.emission = Vec3(le);
  uint32_t id = scene.addMaterial(m, "furnace wall");
  for (int axis = 0; axis < 3; ++axis)
    for (float side : {-1.0f, 1.0f}) addInwardFace(scene, axis, side, id);
  scene.rig.head.position = {0, 0, 0};
  scene.finalize();
  return scene;
}

// A floor at y = 0 (4x4 m) under a point light at (0, 3, 0), and a quad at y = 0.5 over x, z in
// [-0.5, 0.5] whose texture's left half (u < 0.5, x < 0) is cut out (alpha MASK): triangles 0-1
// are the quad, 2-3 the floor.
inline Scene cutOutQuadOverFloor() {
  Scene scene;
  std::vector<uint32_t> texels;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) texels.push_back(200u | 200u << 8 | 200u << 16 | uint32_t(x < 4 ? 0 : 255) << 24);
  Material cut;
  cut.baseColorTexture.texture = int32_t(scene.addTexture("mask", 8, 8, texels, true, WrapMode::ClampToEdge, WrapMode::ClampToEdge));
  cut.alphaMode = AlphaMode::Mask;
  const uint32_t cutId = scene.addMaterial(cut, "cut");
  const uint32_t floorId = scene.addMaterial(Material{}, "floor");
  std::vector<Vec2> uvs[2] = {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {}};
  scene.addMesh("quad", {{-0.5f, 0.5f, -0.5f}, {0.5f, 0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}, {-0.5f, 0.5f, 0.5f}}, {}, uvs,
                {0, 2, 1, 0, 3, 2}, cutId);
  scene.addMesh("floor", {{-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}}, {}, {0, 2, 1, 0, 3, 2}, floorId);
  PunctualLight lamp;
  lamp.position = {0, 3, 0};
  scene.addPunctualLight(lamp, "lamp");
  scene.finalize();
  return scene;
}

}  // namespace pvr::test
