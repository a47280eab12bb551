#pragma once
// `photonvr soak`: the frame loop for many frames while every option the loop lets a user change
// cycles (photons, radius, stereo reuse, foveation, TAA, the denoiser, the rolling map, the surface
// cache, effect levels, the raster pre-pass where Vulkan is present) and the scene is reloaded,
// checking what a long session must keep: no non-finite pixel in any frame, host memory, GPU
// memory and open file descriptors flat after warm-up, p99 steady from the first thousand frames
// to the last, a reload that fails leaving the previous scene rendering.
#include <cstdint>
#include <string>
#include <vector>

#include "pvr/app/loop_commands.h"

namespace pvr {

struct SoakArgs {
  std::string scene;           ///< as given (reloaded by name)
  uint64_t frames = 10000;
  uint64_t changeEvery = 100;  ///< frames between option changes; the states' cycle is kSoakStates x this
  uint64_t reloadEvery = 0;    ///< frames between scene reloads (0: one cycle)
  std::vector<std::string> reloadScenes;  ///< cycled by the reloads (empty: the scene itself again)
  std::string json = "out/soak.json";
  double maxRssGrowthMiB = 8.0;  ///< allowed growth of the resident set over the run after warm-up
  double maxP99Ratio = 0.0;      ///< > 0: the last window's p99 over the first's must not exceed it
};

constexpr int kSoakStates = 10;

// Runs the soak; prints a summary and writes args.json. Returns 0 if every check held, 1 if one
// failed (each failure printed on its own line). Throws pvr::Error for bad arguments.
int runSoakCommand(const SoakArgs& args, const LoopSetup& setup);

}  // namespace pvr
