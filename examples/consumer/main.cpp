// photonvr from an application's side: a scene built in memory (a closed white box with a light
// in its ceiling), a renderer on the best backend, a few frames of a moving head, both eyes back
// as images. Prints what it rendered; exits 1 if a frame is black or not finite.
#include <cmath>
#include <cstdio>
#include <pvr/photonvr.h>

namespace {

// A unit box (inside faces) with a small emitting quad just below its ceiling.
pvr::Scene boxWithLight() {
  pvr::Scene scene;
  pvr::Material white;
  white.albedo = pvr::Vec3(0.75f);
  pvr::Material light;
  light.albedo = pvr::Vec3(0.0f);
  light.emission = pvr::Vec3(12.0f);
  const uint32_t wall = scene.addMaterial(white, "white"), lamp = scene.addMaterial(light, "lamp");
  const std::vector<pvr::Vec3> corners = {{-0.5f, 0, -0.5f}, {0.5f, 0, -0.5f}, {0.5f, 1, -0.5f}, {-0.5f, 1, -0.5f},
                                          {-0.5f, 0, 0.5f},  {0.5f, 0, 0.5f},  {0.5f, 1, 0.5f},  {-0.5f, 1, 0.5f}};
  // Faces wound to face inwards.
  const std::vector<uint32_t> faces = {0, 1, 2, 0, 2, 3,  5, 4, 7, 5, 7, 6,  4, 0, 3, 4, 3, 7,
                                       1, 5, 6, 1, 6, 2,  4, 5, 1, 4, 1, 0,  3, 2, 6, 3, 6, 7};
  scene.addMesh("box", corners, {}, faces, wall);
  const std::vector<pvr::Vec3> quad = {{-0.15f, 0.99f, -0.15f}, {0.15f, 0.99f, -0.15f}, {0.15f, 0.99f, 0.15f},
                                       {-0.15f, 0.99f, 0.15f}};
  scene.addMesh("lamp", quad, {}, {0, 1, 2, 0, 2, 3}, lamp);  // facing down
  scene.finalize();
  scene.rig.head.position = {0.0f, 0.5f, 0.35f};
  return scene;
}

}  // namespace

int main() {
  try {
    pvr::Scene scene = boxWithLight();
    pvr::Renderer renderer(scene);
    renderer.rig().width = 96, renderer.rig().height = 104;
    renderer.options().photonsX = renderer.options().photonsY = 64;
    std::printf("photonvr consumer: %s backend (%s)\n", renderer.backendName().c_str(), renderer.deviceName().c_str());
    for (int f = 0; f < 3; ++f) {
      pvr::Pose head = scene.rig.head;
      head.position.x += 0.02f * float(f);  // the head moves sideways
      const float gaze[2] = {0.5f, 0.5f};
      pvr::FrameResult frame = renderer.renderFrame(head, gaze);
      for (int e = 0; e < 2; ++e) {
        double sum = 0;
        for (const pvr::Vec3& c : frame.eyes[e].image.pixels) sum += double(c.x + c.y + c.z) / 3.0;
        const double mean = sum / double(frame.eyes[e].image.pixels.size());
        std::printf("frame %d, %s eye: %dx%d, mean radiance %.4f, %.2f ms\n", f, e ? "right" : "left",
                    frame.eyes[e].image.width, frame.eyes[e].image.height, mean, frame.timings.eyeMs[e]);
        if (!(mean > 0.0) || !std::isfinite(mean)) {
          std::fprintf(stderr, "photonvr consumer: the %s eye is black or not finite\n", e ? "right" : "left");
          return 1;
        }
      }
    }
  } catch (const pvr::Error& e) {
    std::fprintf(stderr, "photonvr consumer: %s\n", e.what());
    return 1;
  }
  return 0;
}
