#include "pvr/image/image_compare.h"

#include <cmath>
#include <limits>

#include "pvr/image/image_io.h"
#include "pvr/util/error.h"

namespace pvr {

ImageComparison compareDisplayed(const Image& test, const Image& reference, const std::vector<uint8_t>& mask,
                                 float exposure) {
  if (test.width != reference.width || test.height != reference.height)
    throw Error("cannot compare a " + std::to_string(test.width) + "x" + std::to_string(test.height) + " image with a " +
                std::to_string(reference.width) + "x" + std::to_string(reference.height) + " one");
  if (!mask.empty() && mask.size() != reference.pixels.size()) throw Error("the comparison mask has the wrong size");
  ImageComparison out;
  double squared = 0, absolute = 0;
  size_t over = 0;
  for (size_t i = 0; i < reference.pixels.size(); ++i) {
    if (!mask.empty() && !mask[i]) continue;
    float worst = 0;
    for (int c = 0; c < 3; ++c) {
      float d = linearToSrgb(test.pixels[i][c] * exposure) - linearToSrgb(reference.pixels[i][c] * exposure);
      squared += double(d) * d;
      absolute += std::fabs(double(d));
      worst = std::fmax(worst, std::fabs(d));
    }
    over += worst > 0.01f ? 1 : 0;
    ++out.pixels;
  }
  if (out.pixels == 0) return out;
  out.meanSquaredError = squared / (3.0 * double(out.pixels));
  out.meanAbsoluteDifference = absolute / (3.0 * double(out.pixels));
  out.psnr = out.meanSquaredError > 0 ? 10.0 * std::log10(1.0 / out.meanSquaredError)
                                      : std::numeric_limits<double>::infinity();
  out.fractionOver1Percent = double(over) / double(out.pixels);
  return out;
}

}  // namespace pvr
