#pragma once
// photonvr's renderers: the frame pipeline (pvr/pipeline) over the backend of your choice, the
// CPU reference (Embree + TBB) or CUDA.
#include <memory>
#include <string>

#include "pvr/pipeline/frame_renderer.h"

namespace pvr {

class Scene;

enum class BackendKind : int { Cpu = 0, Cuda = 1, Auto = 2 };

// "cpu" | "cuda" | "auto"; throws pvr::Error naming --backend otherwise.
BackendKind parseBackendKind(const std::string& text);

// True if this build has the CUDA backend and a CUDA GPU is usable; otherwise `why` says why not.
bool cudaBackendAvailable(std::string* why = nullptr);

// The backend for `kind` (Auto: CUDA if available, else CPU). Throws pvr::Error for Cuda when no
// GPU can be used. The scene must outlive it.
std::unique_ptr<FrameBackend> makeFrameBackend(BackendKind kind, const Scene& scene);
std::unique_ptr<FrameRenderer> makeFrameRenderer(BackendKind kind, const Scene& scene);

}  // namespace pvr
