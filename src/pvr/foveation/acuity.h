#pragma once
// How finely the eye resolves detail away from the gaze point, and the sample spacing that follows.
//
// Two models, both in degrees of visual angle as functions of eccentricity e (degrees from the
// gaze direction):
//  - linear minimum angle of resolution (Guenter et al. 2012, "Foveated 3D graphics"):
//      omega(e) = omega0 + m * e, omega0 ~ 1/48 deg, m ~ 0.022-0.0275 deg/deg;
//    a sample every omega(e) degrees resolves the finest detail the eye sees there;
//  - Geisler & Perry (1998) contrast threshold model, cutoff frequency
//      f_c(e) = e2 * ln(1 / CT0) / (alpha * (e + e2)) cycles/deg, alpha = 0.106, e2 = 2.3 deg,
//      CT0 = 1/64;
//    Nyquist: a sample every 1 / (2 f_c(e)) degrees.
// Around the gaze, a tracking-error margin keeps full density: eccentricities inside it count as
// zero. The spacing is never finer than the display's own pixel pitch.
#include "pvr/math/vec.h"

namespace pvr {

enum class AcuityKind : int { LinearMar = 0, GeislerPerry = 1 };

struct AcuityModel {
  AcuityKind kind = AcuityKind::LinearMar;
  float mar0Deg = 1.0f / 48.0f;   ///< omega0
  float marSlope = 0.022f;        ///< m, degrees of MAR per degree of eccentricity
  float alpha = 0.106f;           ///< Geisler-Perry spatial frequency decay
  float e2Deg = 2.3f;             ///< Geisler-Perry half-resolution eccentricity
  float contrastThreshold0 = 1.0f / 64.0f;  ///< CT0
  float gazeMarginDeg = 5.0f;     ///< full density this far from the gaze (eye-tracking error)

  // The finest spacing the eye can use at eccentricity e, in degrees (no display cap).
  PVR_HOST_DEVICE float acuitySpacingDeg(float eccentricityDeg) const {
    float e = fmaxf(eccentricityDeg - gazeMarginDeg, 0.0f);
    if (kind == AcuityKind::LinearMar) return mar0Deg + marSlope * e;
    float cutoff = e2Deg * logf(1.0f / contrastThreshold0) / (alpha * (e + e2Deg));  // cycles/deg
    return 0.5f / cutoff;
  }

  // Sample spacing at eccentricity e on a display whose pixels are `pixelPitchDeg` wide there.
  PVR_HOST_DEVICE float sampleSpacingDeg(float eccentricityDeg, float pixelPitchDeg) const {
    return fmaxf(acuitySpacingDeg(eccentricityDeg), pixelPitchDeg);
  }
};

}  // namespace pvr
