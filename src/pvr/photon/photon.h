#pragma once
// The photon record stored in both photon maps.
#include "pvr/math/vec.h"

namespace pvr {

struct Photon {    // 36 bytes
  Vec3 position;   // 12 bytes: where it landed on a diffuse surface
  Vec3 power;      // 12 bytes: flux (W) per RGB channel
  Vec3 direction;  // 12 bytes: unit travel direction when it arrived
};

// Squared distance used by every photon query, so that brute force and the maps agree bitwise.
PVR_HOST_DEVICE inline float photonDistance2(Vec3 q, Vec3 p) { return lengthSquared(p - q); }

}  // namespace pvr
