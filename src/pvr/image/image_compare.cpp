#include "pvr/image/image_compare.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pvr/image/image_io.h"
#include "pvr/util/error.h"

namespace pvr {

namespace {

void checkComparable(const Image& test, const Image& reference, const std::vector<uint8_t>& mask) {
  if (test.width != reference.width || test.height != reference.height)
    throw Error("cannot compare a " + std::to_string(test.width) + "x" + std::to_string(test.height) + " image with a " +
                std::to_string(reference.width) + "x" + std::to_string(reference.height) + " one");
  if (!mask.empty() && mask.size() != reference.pixels.size()) throw Error("the comparison mask has the wrong size");
}

float displayedLuminance(Vec3 linear, float exposure) {
  return 0.2126f * linearToSrgb(linear.x * exposure) + 0.7152f * linearToSrgb(linear.y * exposure) +
         0.0722f * linearToSrgb(linear.z * exposure);
}

// Separable Gaussian blur (sigma 1.5, radius 5) with the window renormalised at the borders.
std::vector<double> gaussianBlur(const std::vector<double>& in, int width, int height) {
  double kernel[11], kernelSum = 0;
  for (int i = 0; i < 11; ++i) kernelSum += kernel[i] = std::exp(-double((i - 5) * (i - 5)) / (2 * 1.5 * 1.5));
  for (double& k : kernel) k /= kernelSum;
  std::vector<double> rows(in.size()), out(in.size());
  for (int pass = 0; pass < 2; ++pass) {
    const std::vector<double>& src = pass == 0 ? in : rows;
    std::vector<double>& dst = pass == 0 ? rows : out;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        double sum = 0, weight = 0;
        for (int i = -5; i <= 5; ++i) {
          int sx = pass == 0 ? x + i : x, sy = pass == 0 ? y : y + i;
          if (sx < 0 || sy < 0 || sx >= width || sy >= height) continue;
          sum += kernel[i + 5] * src[size_t(sy) * width + sx];
          weight += kernel[i + 5];
        }
        dst[size_t(y) * width + x] = sum / weight;
      }
  }
  return out;
}

}  // namespace

ImageComparison compareDisplayed(const Image& test, const Image& reference, const std::vector<uint8_t>& mask,
                                 float exposure) {
  checkComparable(test, reference, mask);
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

double relativeMse(const Image& test, const Image& reference, const std::vector<uint8_t>& mask, float exposure) {
  checkComparable(test, reference, mask);
  double relative = 0;
  size_t pixels = 0;
  for (size_t i = 0; i < reference.pixels.size(); ++i) {
    if (!mask.empty() && !mask[i]) continue;
    for (int c = 0; c < 3; ++c) {
      const double x = double(test.pixels[i][c]) * exposure, y = double(reference.pixels[i][c]) * exposure;
      relative += (x - y) * (x - y) / (y * y + kRelMseRegulariser);
    }
    ++pixels;
  }
  return pixels ? relative / (3.0 * double(pixels)) : 0.0;
}

ReferenceError compareToReference(const Image& test, const Image& reference, const std::vector<uint8_t>& mask,
                                  float exposure) {
  checkComparable(test, reference, mask);
  ReferenceError out;
  const ImageComparison displayed = compareDisplayed(test, reference, mask, exposure);
  out.psnr = displayed.psnr;
  out.pixels = displayed.pixels;
  if (out.pixels == 0) return out;
  double testSum = 0, referenceSum = 0;
  const size_t n = reference.pixels.size();
  std::vector<double> a(n), b(n);
  for (size_t i = 0; i < n; ++i) {
    a[i] = displayedLuminance(test.pixels[i], exposure);
    b[i] = displayedLuminance(reference.pixels[i], exposure);
    if (!mask.empty() && !mask[i]) continue;
    testSum += luminance(test.pixels[i]);
    referenceSum += luminance(reference.pixels[i]);
  }
  out.relMse = relativeMse(test, reference, mask, exposure);
  out.meanRatio = referenceSum > 0 ? testSum / referenceSum : (testSum == 0 ? 1.0 : std::numeric_limits<double>::infinity());
  // SSIM from local means, variances and covariance (all Gaussian-weighted).
  const int w = reference.width, h = reference.height;
  std::vector<double> aa(n), bb(n), ab(n);
  for (size_t i = 0; i < n; ++i) aa[i] = a[i] * a[i], bb[i] = b[i] * b[i], ab[i] = a[i] * b[i];
  const std::vector<double> muA = gaussianBlur(a, w, h), muB = gaussianBlur(b, w, h);
  const std::vector<double> sAA = gaussianBlur(aa, w, h), sBB = gaussianBlur(bb, w, h), sAB = gaussianBlur(ab, w, h);
  const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
  double ssim = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!mask.empty() && !mask[i]) continue;
    double varA = std::max(sAA[i] - muA[i] * muA[i], 0.0), varB = std::max(sBB[i] - muB[i] * muB[i], 0.0);
    double cov = sAB[i] - muA[i] * muB[i];
    ssim += (2 * muA[i] * muB[i] + c1) * (2 * cov + c2) / ((muA[i] * muA[i] + muB[i] * muB[i] + c1) * (varA + varB + c2));
  }
  out.ssim = ssim / double(out.pixels);
  return out;
}

size_t nonFinitePixels(const Image& image) {
  return size_t(std::count_if(image.pixels.begin(), image.pixels.end(), [](const Vec3& c) { return !isFinite(c); }));
}

}  // namespace pvr
