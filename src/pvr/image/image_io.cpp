#include "pvr/image/image_io.h"

#include <ImfRgbaFile.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "pvr/util/error.h"

namespace pvr {

float linearToSrgb(float v) {
  v = std::clamp(std::isfinite(v) ? v : 0.0f, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

void writePng(const Image& image, const std::string& path, float exposure) {
  std::vector<unsigned char> bytes(size_t(image.width) * image.height * 3);
  for (size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      bytes[3 * i + c] = (unsigned char)std::lround(255.0f * linearToSrgb(image.pixels[i][c] * exposure));
  if (!stbi_write_png(path.c_str(), image.width, image.height, 3, bytes.data(), image.width * 3))
    throw Error("cannot write '" + path + "'");
}

void writeExr(const Image& image, const std::string& path) {
  std::vector<Imf::Rgba> rgba(image.pixels.size());
  for (size_t i = 0; i < rgba.size(); ++i)
    rgba[i] = Imf::Rgba(image.pixels[i].x, image.pixels[i].y, image.pixels[i].z, 1.0f);
  try {
    Imf::RgbaOutputFile file(path.c_str(), image.width, image.height, Imf::WRITE_RGBA);
    file.setFrameBuffer(rgba.data(), 1, size_t(image.width));
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    throw Error("cannot write '" + path + "': " + e.what());
  }
}

void writeImage(const Image& image, const std::string& path, float exposure) {
  std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".png") writePng(image, path, exposure);
  else if (ext == ".exr") writeExr(image, path);
  else throw Error("unsupported image format '" + ext + "' for '" + path + "' (use .png or .exr)");
}

}  // namespace pvr
