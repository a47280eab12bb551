#pragma once
// `photonvr bench`: the CPU baseline of the main paper's Table 1 and 2 experiments. For each
// emitted-photon grid and radius it times the kd-tree and hash-grid builds and radius-sum and
// kNN queries at the left eye's hit points, and checks that both maps give the same answers.
#include <string>

namespace pvr {

struct MapBenchArgs {
  std::string scene = "cornell";
  std::string photons = "128x128,256x256,512x512";
  std::string radii = "0.02,0.05,0.1,0.2";
  std::string queries = "360x400";
  int k = 32;
  int repeats = 3;
  std::string json;
};

// Prints the table (and writes JSON if asked); returns 0, or 1 if a self-check failed.
int runMapBench(const MapBenchArgs& args);

}  // namespace pvr
