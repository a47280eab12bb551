#pragma once
// Faults provoked on purpose, so that the reliability tests can show what photonvr does when the
// GPU runs out of memory at any allocation site or the device is lost: PVR_INJECT_FAULT=KIND:N
// makes the Nth event of KIND fail as the driver would report it (docs/reliability.md).
//   gpu-alloc       a CUDA device allocation (cudaMalloc answers cudaErrorMemoryAllocation; the
//                   one pinned host buffer of the photon tracer is not counted)
//   gpu-fault       a CUDA eye pass (a kernel traps before the pass's work: the context is lost,
//                   cudaErrorLaunchFailure, as after a kernel fault or an Xid)
//   vk-alloc        a Vulkan memory allocation (VK_ERROR_OUT_OF_DEVICE_MEMORY)
//   vk-device-lost  a Vulkan queue submission (VK_ERROR_DEVICE_LOST)
// Unset, a check costs one relaxed atomic increment. The command line reads the variable first, so
// a malformed value is refused with one line before anything runs.
#include <cstdint>
#include <string>

namespace pvr {

enum class Fault { GpuAllocation, GpuKernelFault, VulkanAllocation, VulkanDeviceLost };

struct FaultPlan {
  bool active = false;
  Fault kind = Fault::GpuAllocation;
  uint64_t event = 0;  ///< 1-based
};

// Parses "KIND:N" (empty: no fault). Throws pvr::Error naming the variable for anything else.
FaultPlan parseFaultPlan(const std::string& text);

// The plan of PVR_INJECT_FAULT, read once.
const FaultPlan& faultPlan();

// Counts one event of `kind`; true when this is the one that must fail.
bool faultInjected(Fault kind);

// How many events of `kind` this process has counted (for the tests' sweeps and their reports).
uint64_t faultEvents(Fault kind);

const char* faultName(Fault kind);

// For a run that ended well under a plan: how many events of the plan's kind it counted and
// whether the planned one happened (then it was survived, or swallowed), e.g. "fault plan
// gpu-alloc:40: 39 gpu-alloc events, the planned one did not happen". Empty without a plan.
std::string faultPlanReport();

}  // namespace pvr
