#pragma once
// `photonvr bench --suite effects`: Ray-VR's experiments (its Tables I-II and section V) on our
// scenes: mono against stereo, primary rays against the rasterised G-buffer pre-pass, each effect
// level on every material and on chosen material groups (the scene's effect groups: Ray-VR's
// "reflections on statues and wall decorations only"), each with its frame time (mean / p50 / p99)
// and its error against the view's converged reference. With --profile-out it also calibrates the
// budget controller's model for each scene (every knob's step alone: its cost and its error) and
// writes PREFIX_<scene>.json for `--controller-profile`.
#include <nlohmann/json.hpp>

#include "frame_bench.h"
#include "pvr/render/renderer.h"

namespace pvr {

// Returns the number of failed self-checks; appends a JSON row per cell.
int runEffects(const FrameBenchArgs& args, BackendKind kind, nlohmann::json& json);

}  // namespace pvr
