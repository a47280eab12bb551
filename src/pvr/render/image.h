#pragma once
// Linear-RGB float images and their output: sRGB PNG (8-bit, clamped after exposure) and
// linear half-float EXR.
#include <string>
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

float linearToSrgb(float v);
// Throws pvr::Error if the file cannot be written.
void writePng(const Image& image, const std::string& path, float exposure = 1.0f);
void writeExr(const Image& image, const std::string& path);
// Writes PNG or EXR by the path's extension (.png, .exr).
void writeImage(const Image& image, const std::string& path, float exposure = 1.0f);

}  // namespace pvr
