#pragma once
// A linear-RGB float image (image_io.h writes it to PNG and EXR).
#include <vector>

#include "pvr/math/vec.h"

namespace pvr {

struct Image {
  int width = 0, height = 0;
  std::vector<Vec3> pixels;  ///< row-major, top row first
  Image() = default;
  Image(int w, int h) : width(w), height(h), pixels(size_t(w) * h) {}
  Vec3& at(int x, int y) { return pixels[size_t(y) * width + x]; }
  const Vec3& at(int x, int y) const { return pixels[size_t(y) * width + x]; }
};

}  // namespace pvr
