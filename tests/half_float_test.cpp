// Half precision as the denoiser stores its filter levels (util/half_float.h): round to nearest,
// ties to even, subnormals kept, exactly as the GPU's conversion (GpuBackend.HalfFloatsAreTheHostsToTheBit).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>

#include "pvr/util/half_float.h"

namespace pvr {
namespace {

TEST(HalfFloat, EveryHalfRoundTrips) {
  for (uint32_t h = 0; h < 0x10000u; ++h) {
    const bool nan = (h & 0x7c00u) == 0x7c00u && (h & 0x3ffu);
    if (nan) {
      EXPECT_TRUE(std::isnan(halfValue(uint16_t(h))));
      continue;
    }
    EXPECT_EQ(halfBits(halfValue(uint16_t(h))), h) << std::hex << h;
  }
}

TEST(HalfFloat, RoundsToNearestTiesToEven) {
  EXPECT_EQ(halfBits(1.0f), 0x3c00u);
  EXPECT_EQ(halfBits(1.0f + std::ldexp(1.0f, -11)), 0x3c00u);      // a tie: to the even 1.0
  EXPECT_EQ(halfBits(1.0f + 3 * std::ldexp(1.0f, -11)), 0x3c02u);  // a tie: to the even 1 + 2^-9
  EXPECT_EQ(halfBits(1.0f + std::ldexp(1.0f, -11) + std::ldexp(1.0f, -20)), 0x3c01u);  // past the tie: up
  EXPECT_EQ(halfBits(std::ldexp(1.0f, -24)), 0x0001u);      // the smallest subnormal
  EXPECT_EQ(halfBits(std::ldexp(1.0f, -25)), 0x0000u);      // half of it: a tie, to even (zero)
  EXPECT_EQ(halfBits(3 * std::ldexp(1.0f, -25)), 0x0002u);  // 1.5 of it: a tie, to even (2)
  EXPECT_EQ(halfBits(kHalfMax), 0x7bffu);
  EXPECT_EQ(halfBits(65519.0f), 0x7bffu);  // below the midpoint to infinity
  EXPECT_EQ(halfBits(65520.0f), 0x7c00u);  // the midpoint: infinity (the denoiser clamps first)
  EXPECT_EQ(halfBits(-2.0f), 0xc000u);
  // Every float within a quarter ulp of a half's value rounds to that half.
  for (uint32_t h = 0x0400u; h < 0x7bffu; h += 7) {
    const float v = halfValue(uint16_t(h)), ulp = halfValue(uint16_t(h + 1)) - v;
    EXPECT_EQ(halfBits(v + 0.25f * ulp), h);
    EXPECT_EQ(halfBits(v + 0.75f * ulp), h + 1);
  }
}

}  // namespace
}  // namespace pvr
