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

// Pixels with a NaN or infinite channel (the GPU counts its images' on the device:
// cuda/image_checks.h).
size_t nonFinitePixels(const Image& image);

// Compares `test` with `reference` over the pixels whose `mask` entry is non-zero (every pixel if
// the mask is empty). Throws pvr::Error if the sizes differ.
ImageComparison compareDisplayed(const Image& test, const Image& reference, const std::vector<uint8_t>& mask = {},
                                 float exposure = 1.0f);

// The relative MSE's regulariser: (x - y)^2 / (y^2 + kRelMseRegulariser).
constexpr double kRelMseRegulariser = 0.01;

// Error against a converged reference, the figures the rendering literature reports.
struct ReferenceError {
  // Relative MSE in linear radiance: mean over pixels and channels of (x - y)^2 / (y^2 + 0.01)
  // (Rousselle et al.'s regularised form: dark pixels do not dominate). Exposure-independent up
  // to the regulariser.
  double relMse = 0;
  double psnr = 0;  ///< of the displayed (sRGB-encoded, clamped) images, peak 1
  // Mean structural similarity (Wang et al. 2004) of the displayed luminance: 11x11 Gaussian
  // window (sigma 1.5), K1 = 0.01, K2 = 0.03; 1 for identical images.
  double ssim = 0;
  double meanRatio = 0;  ///< mean linear luminance of test / of reference (bias: 1 is unbiased)
  size_t pixels = 0;
};

// ReferenceError::relMse alone (no SSIM: a fraction of the time, for loops that compare many
// frames). Masked as compareDisplayed; 0 where no pixel is compared. Throws pvr::Error if the
// sizes differ.
double relativeMse(const Image& test, const Image& reference, const std::vector<uint8_t>& mask = {}, float exposure = 1.0f);

// Compares `test` with `reference` (masked as compareDisplayed; SSIM's windows are centred on
// masked-in pixels). Throws pvr::Error if the sizes differ.
ReferenceError compareToReference(const Image& test, const Image& reference, const std::vector<uint8_t>& mask = {},
                                  float exposure = 1.0f);

}  // namespace pvr
