#pragma once
// `photonvr bench` suites that time whole frames and the GPU's building blocks:
//  - tables: the main paper's Tables 1-4 (kd-tree vs hash grid, heap vs no heap, single vs
//    hybrid kernel, with vs without shared memory), every cell a full stereo frame (photons
//    traced, map built, both eyes shaded) timed over many frames after warm-up;
//  - rays: rays per second of the CUDA traversal (primary, shadow, diffuse);
//  - grid: the hash-grid build of 1M photons on the GPU;
//  - stereo: the paper's empty Table 5, separate rendering against binocular reuse (scatter, the
//    paper's; gather, ours), with the right eye's reuse fraction, cost and image quality;
//  - foveation: foveated against full-resolution frames, and the temporal flicker with and without TAA;
//  - scenes: textured scenes (Dabrovic Sponza, Sibenik) with full shading: separate and gather
//    frames, the cost of texture sampling, and each image's error against a converged reference;
//  - quality: raw, TAA and denoised frames against converged references (quality_bench.h);
//  - effects: Ray-VR's experiments, mono / stereo, rays / raster pre-pass, effect levels (effects_bench.h).
// Every suite checks its own results and says which GPU, resolution, photons and radius it ran.
// Timings are tail latencies (one slow frame drops a frame in the headset): every frame cell keeps
// each timed frame's wall time and stage times and reports their mean, p50, p99 and max
// (pvr/util/latency_stats.h); the tables print mean / p99, the JSON has all four.
#include <string>

namespace pvr {

struct FrameBenchArgs {
  std::string suite = "tables";  ///< tables | rays | grid | stereo | foveation | all
  std::string scene = "cornell";
  std::string raysScene = "cornell,cornell-dense";
  std::string backend = "auto";
  std::string tables = "1,2,3,4";
  std::string stereo = "separate,scatter,gather";  ///< Table 5's columns
  std::string stereoScenes = "cornell,cornell-caustics";  ///< Table 5 on the first; the others: one row
  std::string eyeSize;  ///< empty: the scene's rig (1440x1600)
  std::string scenes = "scenes/dabrovic-sponza.json,scenes/sibenik.json,cornell-dense";  ///< scenes suite (cornell-dense: the per-ray yardstick); absent meshes: skipped
  float sceneRadius = 0.15f;  ///< scenes suite: the search radius, scene units
  int referencePasses = 64;   ///< tables, scenes and quality suites: passes of the progressive reference (1024x1024 photons each)
  std::string qualityScenes = "cornell,scenes/dabrovic-sponza.json";  ///< quality suite
  std::string qualityImages;  ///< quality suite: PNG prefix (empty: none)
  bool qualityStill = true;   ///< quality suite: the still head's 450 frames too (--no-quality-still: the moving head's alone)
  std::string qualityVariants;  ///< quality suite: variant names separated by ';' (empty: all)
  std::string effectsScenes = "cornell-caustics,cornell-dense,scenes/dabrovic-sponza.json,scenes/sibenik.json";  ///< effects suite
  std::string profileOut;     ///< effects suite: the controller's calibrated profiles; controller suite: with the walk's quality model; PREFIX_<scene>.json (empty: none)
  std::string walks;          ///< controller suite: SCENE=TRAJECTORY,...
  std::string budgets = "11.1,5.5";  ///< controller suite: frame budgets, ms
  std::string profiles;       ///< controller suite: read PREFIX_<scene>.json where it exists (else the generic model)
  int errorEvery = 45;        ///< controller suite: a reference view every this many frames
  int fixedStride = 1;        ///< controller suite: fixed settings render every this many frames of the walk
  int frames = 300;  ///< timed frames per cell (with fewer than 100, p99 is the max)
  int warmup = 10;
  int k = 32;
  std::string json;
};

// Returns 0, or 1 if a self-check failed.
int runFrameBench(const FrameBenchArgs& args);

}  // namespace pvr
