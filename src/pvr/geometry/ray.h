#pragma once
// Rays and the hits every intersector reports (Embree's and our CUDA traversal's convention),
// below cameras, shading and acceleration structures so that each can use them.
#include <cmath>
#include <cstdint>

#include "pvr/math/vec.h"

namespace pvr {

struct Ray {
  Vec3 origin;
  Vec3 dir;
};

struct Hit {
  float t = INFINITY;
  uint32_t primId = ~0u;
  float u = 0, v = 0;  ///< barycentrics of vertices 1 and 2
  PVR_HOST_DEVICE bool valid() const { return primId != ~0u; }
};

}  // namespace pvr
