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

}  // namespace pvr::test
