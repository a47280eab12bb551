#include "pvr/cuda/cuda_util.cuh"
#include "pvr/cuda/injected_fault.cuh"

namespace pvr::cuda {
namespace {

__global__ void trapKernel() { __trap(); }

}  // namespace

void launchInjectedFault(cudaStream_t stream) { launch("injected fault", trapKernel, 1, 1, 0, stream); }

}  // namespace pvr::cuda
