#pragma once
// Traversal stacks in shared memory: each thread of a block gets a column of one array, so pushes
// and pops stay on the multiprocessor instead of being written through to L2 (local memory).
// Column layout: word i of thread t at [i * Threads + t]; the threads of a warp always touch
// distinct banks, whatever their stack depths.
#include "pvr/accel/bvh_traversal.h"
#include "pvr/accel/wide_bvh_traversal.h"

namespace pvr::cuda {

template <class Intersector>
struct TraversalStackWords {
  static constexpr int value = Intersector::kStackSize;  // one word per entry
};
template <>
struct TraversalStackWords<WideBvhIntersector> {
  static constexpr int value = WideBvhIntersector::kStackWords;
};

// The intersector for the calling thread of a block of exactly `Threads` threads (any shape).
template <int Threads, class Intersector>
__device__ inline Intersector withSharedStack(Intersector intersector) {
  static_assert(Threads % 32 == 0, "whole warps, so that each warp's columns fall in distinct banks");
  __shared__ int32_t stacks[TraversalStackWords<Intersector>::value * Threads];
  const unsigned t = threadIdx.x + blockDim.x * (threadIdx.y + blockDim.y * threadIdx.z);
  intersector.sharedStack = stacks + t;
  intersector.sharedStride = Threads;
  return intersector;
}

}  // namespace pvr::cuda
