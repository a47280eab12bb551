// Blue-noise sampling (PixelSampling::BlueNoise, util/blue_noise.h): the mask is the
// void-and-cluster generator's output and is blue; each dimension's values are exactly evenly
// spread over a tile and stratified over frames, and uniform over scrambles; and on a rendered
// Cornell box the error is the white stream's per pixel (same variance, no bias) but far lower
// once filtered in space or accumulated over frames.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "pvr/cpu/cpu_frame_backend.h"
#include "pvr/image/image_compare.h"
#include "pvr/scene/scene.h"
#include "pvr/util/blue_noise_generator.h"
#include "pvr/util/rng.h"

namespace pvr {
namespace {

constexpr int kSide = kBlueNoiseSize;
constexpr int kCells = kSide * kSide;

TEST(BlueNoise, MaskIsTheGeneratorsOutputAndAPermutation) {
  const std::vector<uint16_t> ranks = voidAndClusterRanks(kSide, 1.9, 1);
  ASSERT_EQ(ranks.size(), size_t(kCells));
  std::vector<int> seen(kCells, 0);
  for (int i = 0; i < kCells; ++i) {
    EXPECT_EQ(ranks[i], kBlueNoiseRanks[i]) << "blue_noise_mask.inc is not voidAndClusterRanks(64, 1.9, 1) at " << i;
    ASSERT_LT(kBlueNoiseRanks[i], kCells);
    ++seen[kBlueNoiseRanks[i]];
  }
  for (int r = 0; r < kCells; ++r) EXPECT_EQ(seen[r], 1) << "rank " << r;
}

// The share of a tile's power (DFT, mean removed) at spatial frequencies below 1/8 cycle per pixel,
// over the share those frequencies hold of the frequency plane: 1 for white noise on average.
double lowFrequencyPowerRatio(const std::vector<double>& tile) {
  const int n = kSide;
  double mean = 0;
  for (double v : tile) mean += v;
  mean /= double(tile.size());
  std::vector<std::complex<double>> rows(tile.size()), full(tile.size());
  const double step = -2.0 * 3.14159265358979323846 / n;
  for (int y = 0; y < n; ++y)
    for (int u = 0; u < n; ++u) {
      std::complex<double> s = 0;
      for (int x = 0; x < n; ++x) s += (tile[size_t(y) * n + x] - mean) * std::polar(1.0, step * u * x);
      rows[size_t(y) * n + u] = s;
    }
  double low = 0, all = 0;
  int lowCount = 0, allCount = 0;
  for (int v = 0; v < n; ++v)
    for (int u = 0; u < n; ++u) {
      std::complex<double> s = 0;
      for (int y = 0; y < n; ++y) s += rows[size_t(y) * n + u] * std::polar(1.0, step * v * y);
      if (u == 0 && v == 0) continue;
      const double fu = (u <= n / 2 ? u : u - n) / double(n), fv = (v <= n / 2 ? v : v - n) / double(n);
      const double power = std::norm(s);
      all += power, ++allCount;
      if (std::sqrt(fu * fu + fv * fv) < 0.125) low += power, ++lowCount;
    }
  return (low / lowCount) / (all / allCount);
}

TEST(BlueNoise, MaskHasLittlePowerAtLowFrequencies) {
  std::vector<double> mask(kCells), white(kCells);
  for (int i = 0; i < kCells; ++i) mask[i] = kBlueNoiseRanks[i], white[i] = toUnitFloat(hashCombine(7, uint32_t(i)));
  const double blue = lowFrequencyPowerRatio(mask), reference = lowFrequencyPowerRatio(white);
  EXPECT_LT(blue, 0.1) << "white noise: " << reference;
  EXPECT_GT(reference, 0.5);
  EXPECT_LT(reference, 2.0);
}

// One frame's values of a dimension over a 64x64 block of pixels: the mask's ranks, rotated by one
// constant, so every 1/64 of [0, 1) holds exactly 64 of them.
TEST(BlueNoise, EachDimensionIsEvenlySpreadOverATile) {
  for (uint32_t scramble : {1u, 0xdeadbeefu})
    for (uint32_t index : {0u, 1u, 77u})
      for (uint32_t d = 0; d < kBlueNoiseDims; ++d) {
        std::vector<int> bins(kSide, 0);
        for (uint32_t y = 100; y < 100 + kSide; ++y)
          for (uint32_t x = 30; x < 30 + kSide; ++x) {
            CounterRng rng(5, y * 1000 + x, 0);
            rng.useBlueNoise(x, y, index, scramble);
            for (uint32_t skip = 0; skip < d; ++skip) rng.nextBits();
            ++bins[size_t(rng.uniform() * kSide)];
          }
        for (int b = 0; b < kSide; ++b) ASSERT_EQ(bins[b], kSide) << "dimension " << d << ", bin " << b;
      }
}

TEST(BlueNoise, RadicalInverseIsHaltonsToThe32ndBit) {
  EXPECT_EQ(radicalInverseBits(0, 2), 0u);
  EXPECT_EQ(radicalInverseBits(1, 2), 0x80000000u);
  EXPECT_EQ(radicalInverseBits(6, 2), 0x60000000u);  // 110b -> 0.011b
  EXPECT_EQ(radicalInverseBits(0xffffffffu, 2), 0xffffffffu);
  EXPECT_EQ(radicalInverseBits(1, 3), uint32_t((uint64_t(1) << 32) / 3));
  EXPECT_EQ(radicalInverseBits(7, 5), uint32_t((uint64_t(2 * 5 + 1) << 32) / 25));  // 12 base 5 -> 0.21
  for (uint32_t base : {3u, 5u, 7u, 11u})
    for (uint32_t k : {1u, 2u, 99u, 12345u, 4000000000u}) {
      double expected = 0, f = 1.0;
      for (uint32_t v = k; v; v /= base) f /= base, expected += f * (v % base);
      EXPECT_NEAR(radicalInverseBits(k, base) / 4294967296.0, expected, 1e-8) << k << " base " << base;
    }
}

// One pixel over 64 frames (sample numbers 0..63), as TAA or a still head's refinement
// accumulates them: the mean of a shadow-like integrand of three consecutive dimensions (a light
// chosen with probability 0.3, a disc of the light's square visible) is closer to its integral than
// with independent numbers, for every three consecutive dimensions.
TEST(BlueNoise, EachPixelsFramesIntegrateBetterThanIndependentNumbers) {
  constexpr int kFrames = 64, kPixels = 256;
  const double exact = 0.3 * 3.14159265358979323846 * 0.16;
  for (uint32_t d = 0; d + 3 <= kBlueNoiseDims; ++d) {
    double squared[2] = {0, 0};  // blue, white
    for (uint32_t pixel = 0; pixel < kPixels; ++pixel) {
      double sum[2] = {0, 0};
      for (uint32_t k = 0; k < kFrames; ++k)
        for (int variant = 0; variant < 2; ++variant) {
          CounterRng rng(3, pixel, k);
          if (variant == 0) rng.useBlueNoise(pixel % 16 * 7, pixel / 16 * 5, k, 11);
          for (uint32_t skip = 0; skip < d; ++skip) rng.nextBits();
          const float pick = rng.uniform(), u1 = rng.uniform() - 0.5f, u2 = rng.uniform() - 0.5f;
          sum[variant] += pick < 0.3f && u1 * u1 + u2 * u2 < 0.16f;
        }
      for (int variant = 0; variant < 2; ++variant)
        squared[variant] += (sum[variant] / kFrames - exact) * (sum[variant] / kFrames - exact) / kPixels;
    }
    EXPECT_LT(squared[0], 0.6 * squared[1]) << "dimensions " << d << ".." << d + 2 << ": " << squared[0] << " vs " << squared[1];
    std::printf("dimensions %u..%u, 64 frames: mean squared error %.3g (blue noise) vs %.3g (independent)\n", d, d + 2,
                squared[0], squared[1]);
  }
}

// Over scrambles (seeds), a value is uniform: its mean, its second moment and its histogram.
TEST(BlueNoise, ValuesAreUniformOverScrambles) {
  constexpr int kScrambles = 40000, kBins = 20;
  for (uint32_t d = 0; d < kBlueNoiseDims; ++d) {
    std::vector<int> bins(kBins, 0);
    double sum = 0, squares = 0;
    for (uint32_t s = 0; s < kScrambles; ++s) {
      CounterRng rng(1, 0, 0);
      rng.useBlueNoise(17, 42, 5, s);
      for (uint32_t skip = 0; skip < d; ++skip) rng.nextBits();
      const double u = rng.uniform();
      sum += u, squares += u * u;
      ++bins[int(u * kBins)];
    }
    EXPECT_NEAR(sum / kScrambles, 0.5, 4.0 * std::sqrt(1.0 / 12.0 / kScrambles)) << d;
    EXPECT_NEAR(squares / kScrambles, 1.0 / 3.0, 0.01) << d;
    double chiSquare = 0;
    for (int b : bins) chiSquare += (b - kScrambles / double(kBins)) * (b - kScrambles / double(kBins)) / (kScrambles / double(kBins));
    EXPECT_LT(chiSquare, 43.8) << d;  // 19 degrees of freedom, p = 0.001
  }
}

// A Cornell box lit by its area light alone (the shadows level: one light sample per pixel, the
// pixel centre fixed), left eye 64x64: frames against the mean of 512 frames of independent numbers.
struct DirectLightFrames {
  Scene scene = builtinScene("cornell");
  FrameRenderer renderer = makeCpuFrameRenderer(scene);
  StereoRig rig = scene.rig;
  DirectLightFrames() { rig.width = rig.height = 64; }
  Image frame(PixelSampling sampling, uint32_t seed, uint32_t sequenceIndex, int samplesPerPixel = 1) {
    RenderOptions o;
    o.gather.samplesPerPixel = samplesPerPixel;
    o.photonsX = o.photonsY = 16;
    o.eyes[1] = false;
    o.gather.overrideEffects = true;
    o.gather.effects = EffectLevel::Shadows;
    o.gather.sampling = sampling;
    o.gather.seed = seed;
    o.gather.sequenceIndex = sequenceIndex;
    return std::move(renderer.render(rig, o).eyes[0].image);
  }
  static Image mean(const std::vector<Image>& images) {
    Image out(images[0].width, images[0].height);
    for (const Image& im : images)
      for (size_t i = 0; i < out.pixels.size(); ++i) out.pixels[i] += im.pixels[i] * (1.0f / float(images.size()));
    return out;
  }
  // Each 4x4 block averaged: what any spatial filter (a denoiser, a display's resampling) does.
  static Image boxFiltered(const Image& in) {
    Image out(in.width / 4, in.height / 4);
    for (int y = 0; y < out.height; ++y)
      for (int x = 0; x < out.width; ++x)
        for (int dy = 0; dy < 4; ++dy)
          for (int dx = 0; dx < 4; ++dx) out.at(x, y) += in.at(4 * x + dx, 4 * y + dy) * (1.0f / 16.0f);
    return out;
  }
};

TEST(BlueNoise, RenderedErrorIsUnbiasedAndFallsUnderFilteringAndAccumulation) {
  DirectLightFrames frames;
  std::vector<Image> white;
  for (uint32_t s = 0; s < 512; ++s) white.push_back(frames.frame(PixelSampling::White, 1000 + s, 0));
  const Image reference = DirectLightFrames::mean(white);
  const Image filteredReference = DirectLightFrames::boxFiltered(reference);

  double raw[2] = {0, 0}, filtered[2] = {0, 0};
  std::vector<Image> blueFrames;
  constexpr int kSeeds = 16;
  for (uint32_t s = 0; s < kSeeds; ++s) {
    const Image b = frames.frame(PixelSampling::BlueNoise, 1 + s, 0), &w = white[s];
    raw[0] += compareToReference(b, reference).relMse / kSeeds, raw[1] += compareToReference(w, reference).relMse / kSeeds;
    filtered[0] += compareToReference(DirectLightFrames::boxFiltered(b), filteredReference).relMse / kSeeds;
    filtered[1] += compareToReference(DirectLightFrames::boxFiltered(w), filteredReference).relMse / kSeeds;
    blueFrames.push_back(b);
  }
  // Per pixel, one sample is one sample: the same error, within the noise of 16 frames.
  EXPECT_GT(raw[0] / raw[1], 0.8) << raw[0] << " vs " << raw[1];
  EXPECT_LT(raw[0] / raw[1], 1.25) << raw[0] << " vs " << raw[1];
  // Spread as blue noise, more of it cancels in a 4x4 box (each dimension is blue on its own; the
  // light sample warps three together, so not all of its error is).
  EXPECT_LT(filtered[0], 0.8 * filtered[1]) << filtered[0] << " vs " << filtered[1];
  // Unbiased: the mean of frames of different seeds is the reference's mean.
  const ReferenceError meanError = compareToReference(DirectLightFrames::mean(blueFrames), reference);
  EXPECT_NEAR(meanError.meanRatio, 1.0, 0.01);

  // 16 frames of a still view accumulated (frame k = number k of each pixel's sequences), against
  // 16 frames of independent numbers.
  std::vector<Image> blueRun, whiteRun;
  for (uint32_t k = 0; k < 16; ++k) {
    blueRun.push_back(frames.frame(PixelSampling::BlueNoise, 1, k));
    whiteRun.push_back(frames.frame(PixelSampling::White, 1, k));
  }
  const double accumulated[2] = {compareToReference(DirectLightFrames::mean(blueRun), reference).relMse,
                                 compareToReference(DirectLightFrames::mean(whiteRun), reference).relMse};
  EXPECT_LT(accumulated[0], 0.6 * accumulated[1]) << accumulated[0] << " vs " << accumulated[1];
  std::printf("relMSE blue / white: raw %.4g / %.4g, 4x4 box %.4g / %.4g, 16 frames %.4g / %.4g\n", raw[0], raw[1],
              filtered[0], filtered[1], accumulated[0], accumulated[1]);
}

// Two samples per pixel (the centre, and a jittered one) over a run of 64 frames of one seed: each
// pixel's mean converges to its own expectation, as with independent numbers (each sample runs
// through the whole sequence with its own scramble, so no sample is held in part of [0, 1)).
TEST(BlueNoise, SeveralSamplesPerPixelConvergeOverFrames) {
  DirectLightFrames frames;
  frames.rig.width = frames.rig.height = 32;
  std::vector<Image> white;
  for (uint32_t s = 0; s < 256; ++s) white.push_back(frames.frame(PixelSampling::White, 5000 + s, 0, 2));
  const Image reference = DirectLightFrames::mean(white);
  std::vector<Image> blueRun, whiteRun;
  for (uint32_t k = 0; k < 64; ++k) {
    blueRun.push_back(frames.frame(PixelSampling::BlueNoise, 3, k, 2));
    whiteRun.push_back(frames.frame(PixelSampling::White, 3, k, 2));
  }
  const double blue = compareToReference(DirectLightFrames::mean(blueRun), reference).relMse;
  const double independent = compareToReference(DirectLightFrames::mean(whiteRun), reference).relMse;
  EXPECT_LT(blue, independent) << blue << " vs " << independent;
  std::printf("2 spp, 64 frames: relMSE %.4g (blue noise) vs %.4g (independent)\n", blue, independent);
}

}  // namespace
}  // namespace pvr
