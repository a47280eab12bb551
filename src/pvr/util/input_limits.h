#pragma once
// The largest inputs photonvr accepts, in one place (docs/reliability.md lists them with the
// options' limits of pvr/pipeline/frame_options.h). Each is refused with a line naming it; an
// application that needs more may raise them before loading.
#include <cstdint>
#include <string>

namespace pvr {

struct InputLimits {
  uint64_t triangles = uint64_t(1) << 27;    ///< per scene, after degenerate ones are dropped (32-bit indices, BVH nodes)
  uint64_t textures = 4096;                  ///< distinct images per scene
  int textureSide = 16384;                   ///< texels per side of one image (the common Vulkan/CUDA 2D limit)
  uint64_t textureBytes = uint64_t(4) << 30;  ///< all of a scene's texels with their mip levels, RGBA8
  uint64_t trajectoryFrames = 1000000;       ///< lines of a trajectory file (3 hours at 90 Hz)
  uint64_t sceneFileBytes = uint64_t(64) << 20;  ///< a JSON scene description (the meshes it names are not counted)
};

inline InputLimits& mutableInputLimits() {
  static InputLimits limits;
  return limits;
}
inline const InputLimits& inputLimits() { return mutableInputLimits(); }
inline void setInputLimits(const InputLimits& limits) { mutableInputLimits() = limits; }

}  // namespace pvr
