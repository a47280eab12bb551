#pragma once
// Choosing a backend: the CPU reference (Embree + TBB) or CUDA.
#include <memory>
#include <string>

#include "pvr/cpu/cpu_renderer.h"
#include "pvr/frame/frame.h"

namespace pvr {

enum class BackendKind : int { Cpu = 0, Cuda = 1, Auto = 2 };

// "cpu" | "cuda" | "auto"; throws pvr::Error naming --backend otherwise.
BackendKind parseBackendKind(const std::string& text);

// True if this build has the CUDA backend and a CUDA GPU is usable; otherwise `why` says why not.
bool cudaBackendAvailable(std::string* why = nullptr);

// The renderer for `kind` (Auto: CUDA if available, else CPU). Throws pvr::Error for Cuda when
// no GPU can be used.
std::unique_ptr<FrameRenderer> makeFrameRenderer(BackendKind kind, const Scene& scene);

}  // namespace pvr
