#pragma once
// Checks of images in GPU memory, run on the GPU so that a check of every frame needs no readback
// of the images (the soak's non-finite check). A plain C++ header.
#include <cstddef>
#include <cstdint>

#include "pvr/math/vec.h"

namespace pvr::cuda {

// The number of pixels with a non-finite component (NaN, +-Inf) among `pixels` linear RGB values at
// `image` (GPU memory), counted on `stream` (cudaStream_t) after the work queued on it; waits for it.
uint64_t countNonFinitePixels(const Vec3* image, size_t pixels, void* stream);

}  // namespace pvr::cuda
