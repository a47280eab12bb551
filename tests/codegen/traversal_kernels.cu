// Ray kernels reduced to one traversal each, for gpu_codegen.sh: their PTX must not touch local
// memory in the traversal loops (apart from the local-stack fallback). A node's boxes or children
// held in arrays indexed by a run-time child, or a copy of the scene view indexed at run time,
// put every node visit through local memory and cost the binary BVH 2-4x of its ray rate.
#include "pvr/cuda/traversal_stack.cuh"

template <class Intersector, bool AnyHit>
__global__ void traceKernel(Intersector sceneIntersector, const pvr::Ray* rays, pvr::Hit* hits, int n) {
  const Intersector intersector = pvr::cuda::withSharedStack<64>(sceneIntersector);
  const int i = int(blockIdx.x * blockDim.x + threadIdx.x);
  if (i >= n) return;
  pvr::Hit hit;
  if (AnyHit) hit.primId = intersector.occluded(rays[i], INFINITY) ? 1u : 0u;
  else intersector.intersect(rays[i], INFINITY, hit);
  hits[i] = hit;
}

template __global__ void traceKernel<pvr::BvhIntersector, false>(pvr::BvhIntersector, const pvr::Ray*, pvr::Hit*, int);
template __global__ void traceKernel<pvr::BvhIntersector, true>(pvr::BvhIntersector, const pvr::Ray*, pvr::Hit*, int);
template __global__ void traceKernel<pvr::WideBvhIntersector, false>(pvr::WideBvhIntersector, const pvr::Ray*, pvr::Hit*, int);
template __global__ void traceKernel<pvr::WideBvhIntersector, true>(pvr::WideBvhIntersector, const pvr::Ray*, pvr::Hit*, int);
