#pragma once
// Linear-RGB float images and their output: sRGB PNG (8-bit, clamped after exposure) and
// linear half-float EXR.
#include <string>
#include <vector>

#include "pvr/image/image.h"

namespace pvr {

float linearToSrgb(float v);
// Throws pvr::Error if the file cannot be written.
void writePng(const Image& image, const std::string& path, float exposure = 1.0f);
void writeExr(const Image& image, const std::string& path);
// Writes PNG or EXR by the path's extension (.png, .exr).
void writeImage(const Image& image, const std::string& path, float exposure = 1.0f);

}  // namespace pvr
