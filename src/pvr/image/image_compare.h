#pragma once
// How far a rendered image is from a reference, as a viewer sees it: both are displayed the way
// the PNG writer does (exposure, clamp to [0, 1], sRGB encoding) and compared per channel.
#include <cstdint>
#include <vector>

#include "pvr/image/image.h"

namespace pvr {

struct ImageComparison {
  double psnr = 0;                ///< dB, peak 1; +infinity for identical images
  double meanSquaredError = 0;
  double meanAbsoluteDifference = 0;  ///< per channel, in display units (0..1)
  double fractionOver1Percent = 0;  ///< pixels with a channel off by more than 0.01 of the display range
  size_t pixels = 0;               ///< pixels compared
};

// Compares `test` with `reference` over the pixels whose `mask` entry is non-zero (every pixel if
// the mask is empty). Throws pvr::Error if the sizes differ.
ImageComparison compareDisplayed(const Image& test, const Image& reference, const std::vector<uint8_t>& mask = {},
                                 float exposure = 1.0f);

}  // namespace pvr
