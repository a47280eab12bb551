#pragma once
// PVR_INJECT_FAULT=gpu-fault:N (pvr/util/fault_injection.h): a kernel that traps, so the CUDA
// context is lost as after a real kernel fault; the error surfaces at the frame's next sync.
#include <cuda_runtime.h>

namespace pvr::cuda {

void launchInjectedFault(cudaStream_t stream);

}  // namespace pvr::cuda
