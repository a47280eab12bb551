#pragma once
// `photonvr bench --suite quality`: what the headset shows against the converged reference of the
// same view, for the raw 1-spp frame, TAA, the denoiser and both: relMSE, SSIM and flicker on a
// moving head (a 2 s sway-and-turn), relMSE after 1 s and 5 s on a still one, and the denoiser's
// cost per stereo frame (mean / p99).
#include <nlohmann/json.hpp>

#include "frame_bench.h"
#include "pvr/render/renderer.h"

namespace pvr {

// Returns the number of failed self-checks; appends a JSON row per variant and head.
int runQuality(const FrameBenchArgs& args, BackendKind kind, nlohmann::json& json);

}  // namespace pvr
