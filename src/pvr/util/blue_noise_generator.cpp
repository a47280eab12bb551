#include "pvr/util/blue_noise_generator.h"

#include <cmath>
#include <stdexcept>

#include "pvr/util/rng.h"

namespace pvr {
namespace {

// A binary pattern on a torus and, for every pixel, the Gaussian-weighted count of set pixels
// around it (in fixed point, so that ties and the result do not depend on float rounding).
class EnergyField {
 public:
  EnergyField(int size, double sigma) : size_(size), kernel_(size_t(size) * size), energy_(size_t(size) * size, 0) {
    for (int dy = 0; dy < size; ++dy)
      for (int dx = 0; dx < size; ++dx) {
        const int tx = std::min(dx, size - dx), ty = std::min(dy, size - dy);  // toroidal distance
        kernel_[size_t(dy) * size + dx] = std::llround(std::exp(-(tx * tx + ty * ty) / (2.0 * sigma * sigma)) * (1 << 24));
      }
  }
  void toggle(std::vector<uint8_t>& bits, int p) {
    const int64_t sign = bits[p] ? -1 : 1;
    bits[p] ^= 1;
    const int px = p % size_, py = p / size_;
    for (int y = 0; y < size_; ++y) {
      const int64_t* row = &kernel_[size_t((y - py + size_) % size_) * size_];
      int64_t* out = &energy_[size_t(y) * size_];
      for (int x = 0; x < size_; ++x) out[x] += sign * row[(x - px + size_) % size_];
    }
  }
  // The set pixel of highest energy (the tightest cluster), or the unset one of lowest (the largest void).
  int tightestCluster(const std::vector<uint8_t>& bits) const { return extreme(bits, 1, true); }
  int largestVoid(const std::vector<uint8_t>& bits) const { return extreme(bits, 0, false); }

 private:
  int extreme(const std::vector<uint8_t>& bits, uint8_t value, bool highest) const {
    int best = -1;
    for (int p = 0; p < int(bits.size()); ++p)
      if (bits[p] == value && (best < 0 || (highest ? energy_[p] > energy_[best] : energy_[p] < energy_[best]))) best = p;
    return best;
  }
  int size_;
  std::vector<int64_t> kernel_, energy_;
};

}  // namespace

std::vector<uint16_t> voidAndClusterRanks(int size, double sigma, uint32_t seed) {
  if (size < 4 || size > 256 || !(sigma > 0.0)) throw std::invalid_argument("voidAndClusterRanks: size 4..256, sigma > 0");
  const int n = size * size;
  // The initial pattern: a tenth of the pixels, set at random, then relaxed by moving the tightest
  // cluster's pixel to the largest void until that undoes itself.
  std::vector<uint8_t> prototype(size_t(n), 0);
  EnergyField field(size, sigma);
  int ones = 0;
  for (uint32_t i = 0; ones < n / 10; ++i) {
    const int p = int(hashCombine(seed, i) % uint32_t(n));
    if (!prototype[p]) field.toggle(prototype, p), ++ones;
  }
  for (;;) {
    const int cluster = field.tightestCluster(prototype);
    field.toggle(prototype, cluster);
    const int hole = field.largestVoid(prototype);
    field.toggle(prototype, hole);
    if (hole == cluster) break;
  }
  std::vector<uint16_t> ranks(size_t(n), 0);
  // Phase 1: the prototype's pixels ranked by removing the tightest cluster first.
  {
    std::vector<uint8_t> bits = prototype;
    EnergyField f = field;
    for (int rank = ones - 1; rank >= 0; --rank) {
      const int p = f.tightestCluster(bits);
      f.toggle(bits, p);
      ranks[p] = uint16_t(rank);
    }
  }
  // Phases 2 and 3: the rest ranked by filling the largest void. (Past half full, the tightest
  // cluster of unset pixels is the same pixel: the two energies add up to a constant.)
  std::vector<uint8_t> bits = prototype;
  for (int rank = ones; rank < n; ++rank) {
    const int p = field.largestVoid(bits);
    field.toggle(bits, p);
    ranks[p] = uint16_t(rank);
  }
  return ranks;
}

}  // namespace pvr
