#pragma once
// Checks of images in GPU memory, run on the GPU so that a check of every frame needs no readback
// of the images (the soak's non-finite check). A plain C++ header.
#include <cstddef>
#include <cstdint>

#include "pvr/math/vec.h"

namespace pvr::cuda {

// Counts the pixels with a non-finite component (NaN, +-Inf) of linear RGB images in GPU memory.
// Holds its two counters (allocated at the first count) from frame to frame.
class NonFiniteCounter {
 public:
  NonFiniteCounter() = default;
  ~NonFiniteCounter();
  NonFiniteCounter(const NonFiniteCounter&) = delete;
  NonFiniteCounter& operator=(const NonFiniteCounter&) = delete;
  // Both eyes' images of `pixels` values each (a null one is skipped), counted on `stream`
  // (cudaStream_t) after the work queued on it; waits for it once. Returns the two counts.
  void count(const Vec3* const images[2], size_t pixels, void* stream, uint64_t counts[2]);

 private:
  unsigned long long* counters_ = nullptr;  // GPU memory, two counters
};

}  // namespace pvr::cuda
