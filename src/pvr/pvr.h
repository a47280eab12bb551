#pragma once
// Marks code that is compiled both for the host and, by nvcc, for the device.
// Everything under math/, util/, camera/, shading/ and photon/ is written this way so the
// CPU (Embree) backend and the CUDA backend run the same algorithm code.
#if defined(__CUDACC__)
#define PVR_HOST_DEVICE __host__ __device__
#define PVR_NOINLINE __noinline__  // a rarely taken path kept out of its callers' register budget
#else
#define PVR_HOST_DEVICE
#define PVR_NOINLINE
#endif

#include <cstdint>

namespace pvr {
constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;
}  // namespace pvr
