#pragma once
// The foveated eye pass's options: which mask, and where each eye looks.
#include <cstddef>

#include "pvr/stereo/vergence.h"

namespace pvr {

struct FoveationMask;  // pvr/foveation/mask.h

// Foveated rendering: rays only through the mask's vertices around each eye's gaze, the image
// reconstructed from them (the foveated ray tracing document).
struct FoveationOptions {
  const FoveationMask* mask = nullptr;  ///< null: every pixel is shaded
  float gaze[2][2] = {{0.5f, 0.5f}, {0.5f, 0.5f}};  ///< per eye, gaze point in [0, 1]^2 of the image (x right, y down)
  /// One gaze for both eyes, as eyes look: gaze[0] is the left eye's, and the right eye fixates
  /// the surface point the left eye's gaze ray meets (vergence); gaze[1] is then ignored.
  bool verge = false;
  // The gaze's pixel for an eye of width x height.
  void gazePixel(int eye, int width, int height, int& x, int& y) const { gazePixelOf(gaze[eye], width, height, x, y); }
  size_t gazePixelIndex(int eye, int width, int height) const {
    int x, y;
    gazePixel(eye, width, height, x, y);
    return size_t(y) * size_t(width) + size_t(x);
  }
};

}  // namespace pvr
