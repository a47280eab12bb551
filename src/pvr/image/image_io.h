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
// 8-bit RGB rows as they are (a display image read back), written as `writePng` writes its bytes.
void writePngRgb(const std::vector<unsigned char>& rgb, int width, int height, const std::string& path);
void writeExr(const Image& image, const std::string& path);
// Reads an EXR's RGB (linear; as writeExr writes them). Throws pvr::Error naming the file if it is
// missing, not an EXR, or of an unsupported size.
Image readExr(const std::string& path);
// Writes PNG or EXR by the path's extension (.png, .exr).
void writeImage(const Image& image, const std::string& path, float exposure = 1.0f);

}  // namespace pvr
