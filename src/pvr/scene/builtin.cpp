// Built-in scenes: the classic Cornell box (Cornell University's measured geometry, in mm,
// scaled by 1/556 so the box is about 1 unit wide, turned to look down -Z) and a caustics
// variant with a mirror sphere and a glass sphere in place of the two blocks.
#include <cmath>

#include "pvr/scene/scene.h"
#include "pvr/util/error.h"

namespace pvr {
namespace {

// Classic Cornell coordinates (mm; viewer at -Z looking +Z, X to the left) to photonvr world
// units (viewer looking -Z, X to the right, box 0.5 units either side of x = 0).
Vec3 cornell(float x, float y, float z) {
  const float s = 1.0f / 556.0f;
  return {(278.0f - x) * s, y * s, (279.6f - z) * s};
}

// A planar quad a-b-c-d (counter-clockwise seen from the side its normal faces).
void addQuad(Scene& scene, const std::string& name, Vec3 a, Vec3 b, Vec3 c, Vec3 d, uint32_t material) {
  scene.addMesh(name, {a, b, c, d}, {}, {0, 1, 2, 0, 2, 3}, material);
}

// A block standing on the floor: its top face's corners (any winding) and its height.
void addBlock(Scene& scene, const std::string& name, const Vec3 top[4], float height, uint32_t material) {
  std::vector<Vec3> v;
  for (int i = 0; i < 4; ++i) v.push_back(top[i]);
  for (int i = 0; i < 4; ++i) v.push_back(top[i] - Vec3(0, height, 0));
  std::vector<uint32_t> idx = {0, 1, 2, 0, 2, 3};
  for (uint32_t i = 0; i < 4; ++i) {
    uint32_t j = (i + 1) % 4;
    idx.insert(idx.end(), {i, i + 4, j + 4, i, j + 4, j});
  }
  scene.addMesh(name, v, {}, idx, material);
}

void addSphere(Scene& scene, const std::string& name, Vec3 center, float radius, uint32_t material) {
  const int rings = 48, segments = 96;
  std::vector<Vec3> v, n;
  std::vector<uint32_t> idx;
  for (int r = 0; r <= rings; ++r) {
    float theta = kPi * float(r) / rings;
    for (int s = 0; s <= segments; ++s) {
      float phi = 2.0f * kPi * float(s) / segments;
      Vec3 dir{sinf(theta) * cosf(phi), cosf(theta), -sinf(theta) * sinf(phi)};
      v.push_back(center + dir * radius);
      n.push_back(dir);
    }
  }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      uint32_t a = r * (segments + 1) + s, b = a + segments + 1;
      if (r > 0) idx.insert(idx.end(), {a, b, a + 1});  // pole rows hold one real triangle
      if (r < rings - 1) idx.insert(idx.end(), {a + 1, b, b + 1});
    }
  scene.addMesh(name, v, n, idx, material);
}

// A sphere with a sinusoidal relief on a fine latitude-longitude grid: many small triangles of
// varied orientation, for measuring ray throughput on over a million triangles.
void addBumpySphere(Scene& scene, const std::string& name, Vec3 centre, float radius, int segments, int rings,
                    uint32_t material) {
  std::vector<Vec3> v;
  std::vector<uint32_t> idx;
  v.reserve(size_t(segments + 1) * (rings + 1));
  for (int j = 0; j <= rings; ++j) {
    float theta = kPi * float(j) / float(rings);
    for (int i = 0; i <= segments; ++i) {
      float phi = 2.0f * kPi * float(i) / float(segments);
      float r = radius * (1.0f + 0.06f * sinf(12.0f * theta) * sinf(10.0f * phi));
      v.push_back(centre + Vec3(r * sinf(theta) * cosf(phi), r * cosf(theta), r * sinf(theta) * sinf(phi)));
    }
  }
  for (int j = 0; j < rings; ++j)
    for (int i = 0; i < segments; ++i) {
      uint32_t a = uint32_t(j * (segments + 1) + i), b = a + 1, c = a + uint32_t(segments + 1), d = c + 1;
      idx.insert(idx.end(), {a, b, c, b, d, c});
    }
  scene.addMesh(name, v, {}, idx, material);
}

enum class CornellContents { Blocks, Spheres, DenseSphere };

Scene cornellBox(CornellContents contents) {
  Scene scene;
  bool caustics = contents == CornellContents::Spheres;
  scene.name = caustics ? "cornell-caustics" : (contents == CornellContents::Blocks ? "cornell" : "cornell-dense");
  Material white, red, green, light;
  white.albedo = {0.73f, 0.73f, 0.73f};
  red.albedo = {0.63f, 0.065f, 0.05f};
  green.albedo = {0.14f, 0.45f, 0.091f};
  light.albedo = {0.78f, 0.78f, 0.78f};
  light.emission = {17.0f, 12.0f, 4.0f};
  uint32_t mWhite = scene.addMaterial(white, "white");
  uint32_t mRed = scene.addMaterial(red, "red");
  uint32_t mGreen = scene.addMaterial(green, "green");
  uint32_t mLight = scene.addMaterial(light, "light");

  addQuad(scene, "floor", cornell(552.8f, 0, 0), cornell(0, 0, 0), cornell(0, 0, 559.2f), cornell(549.6f, 0, 559.2f), mWhite);
  addQuad(scene, "ceiling", cornell(556, 548.8f, 0), cornell(556, 548.8f, 559.2f), cornell(0, 548.8f, 559.2f),
          cornell(0, 548.8f, 0), mWhite);
  addQuad(scene, "back wall", cornell(549.6f, 0, 559.2f), cornell(0, 0, 559.2f), cornell(0, 548.8f, 559.2f),
          cornell(556, 548.8f, 559.2f), mWhite);
  addQuad(scene, "red wall", cornell(552.8f, 0, 0), cornell(549.6f, 0, 559.2f), cornell(556, 548.8f, 559.2f),
          cornell(556, 548.8f, 0), mRed);
  addQuad(scene, "green wall", cornell(0, 0, 559.2f), cornell(0, 0, 0), cornell(0, 548.8f, 0), cornell(0, 548.8f, 559.2f),
          mGreen);
  // The light hangs 0.5 mm below the ceiling and faces down.
  addQuad(scene, "light", cornell(343, 548.3f, 227), cornell(343, 548.3f, 332), cornell(213, 548.3f, 332),
          cornell(213, 548.3f, 227), mLight);

  if (contents == CornellContents::DenseSphere) {
    // The walls' white, its own material so that it is an effect group of its own.
    const uint32_t mSphere = scene.addMaterial(white, "sphere");
    scene.setEffectGroup(mSphere, scene.addEffectGroup("sphere"));
    addBumpySphere(scene, "bumpy sphere", {0.0f, 0.3f, -0.05f}, 0.26f, 1024, 640, mSphere);
  } else if (!caustics) {
    const Vec3 shortTop[4] = {cornell(130, 165, 65), cornell(82, 165, 225), cornell(240, 165, 272), cornell(290, 165, 114)};
    const Vec3 tallTop[4] = {cornell(423, 330, 247), cornell(265, 330, 296), cornell(314, 330, 456), cornell(472, 330, 406)};
    addBlock(scene, "short block", shortTop, 165.0f / 556.0f, mWhite);
    addBlock(scene, "tall block", tallTop, 330.0f / 556.0f, mWhite);
  } else {
    Material mirror, glass;
    mirror.type = MaterialType::Mirror;
    mirror.albedo = {0.95f, 0.95f, 0.95f};
    glass.type = MaterialType::Glass;
    glass.albedo = {1.0f, 1.0f, 1.0f};
    glass.ior = 1.5f;
    uint32_t mMirror = scene.addMaterial(mirror, "mirror");
    uint32_t mGlass = scene.addMaterial(glass, "glass");
    const uint32_t specular = scene.addEffectGroup("specular");
    scene.setEffectGroup(mMirror, specular);
    scene.setEffectGroup(mGlass, specular);
    const float r = 0.17f;
    addSphere(scene, "mirror sphere", {-0.2f, r, -0.22f}, r, mMirror);
    addSphere(scene, "glass sphere", {0.2f, r + 0.02f, 0.1f}, r, mGlass);
  }

  // Head at standing-eye height relative to the box, 1 unit in front of its centre.
  scene.rig.head.position = {0.0f, 0.5f, 1.0f};
  scene.rig.head.orientation = lookAtOrientation(scene.rig.head.position, {0.0f, 0.5f, 0.0f});
  scene.finalize();
  return scene;
}

}  // namespace

std::vector<std::string> builtinSceneNames() { return {"cornell", "cornell-caustics", "cornell-dense"}; }

Scene builtinScene(const std::string& name) {
  if (name == "cornell") return cornellBox(CornellContents::Blocks);
  if (name == "cornell-caustics") return cornellBox(CornellContents::Spheres);
  if (name == "cornell-dense") return cornellBox(CornellContents::DenseSphere);
  throw Error("unknown built-in scene '" + name + "' (built-in scenes: cornell, cornell-caustics, cornell-dense)");
}

}  // namespace pvr
