#pragma once
// `photonvr bench --suite controller`: the budget controller on recorded walks through scenes
// (Ray-VR's section VI, built). For each scene and budget it runs the walk under the controller,
// then the same walk at fixed settings (the settings the controller spent most time in, and a
// ladder of uniform ones), and reports for each the frame time (mean / p50 / p99, frames over the budget) and
// the error against converged references of sampled frames' views. Checks: the controller's p99
// is under the budget with at most 0.5 % of frames over it, and its error is below every fixed
// setting that also meets the budget. The JSON has every frame (time, decision, sampled error)
// for scripts/plot_controller.py.
#include <nlohmann/json.hpp>

#include "frame_bench.h"
#include "pvr/render/renderer.h"

namespace pvr {

int runControllerBench(const FrameBenchArgs& args, BackendKind kind, nlohmann::json& json);

}  // namespace pvr
