#pragma once
// IEEE half precision (binary16) as 16-bit words, host+device: the device's conversion
// instructions, and on the host Imath's (OpenEXR's half type). Both round to nearest, ties to
// even, and keep subnormals, so the CPU and CUDA backends store the same bits for the same float.
#include <cstdint>

#include "pvr/pvr.h"

#if defined(__CUDACC__)
#include <cuda_fp16.h>
#endif
#if !defined(__CUDA_ARCH__)
// The conversions by arithmetic, not Imath's lookup table: nothing to link.
#define IMATH_HALF_NO_LOOKUP_TABLE
#include <Imath/half.h>
#endif

namespace pvr {

constexpr float kHalfMax = 65504.0f;  ///< the largest finite half

PVR_HOST_DEVICE inline uint16_t halfBits(float f) {
#ifdef __CUDA_ARCH__
  return __half_as_ushort(__float2half_rn(f));
#else
  return imath_float_to_half(f);
#endif
}

PVR_HOST_DEVICE inline float halfValue(uint16_t bits) {
#ifdef __CUDA_ARCH__
  return __half2float(__ushort_as_half(bits));
#else
  return imath_half_to_float(bits);
#endif
}

}  // namespace pvr
