#include "pvr/image/image_io.h"

#include <ImfRgbaFile.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "pvr/image/display_encoding.h"
#include "pvr/util/error.h"

namespace pvr {

float linearToSrgb(float v) { return srgbEncode(v); }

void writePng(const Image& image, const std::string& path, float exposure) {
  std::vector<unsigned char> bytes(size_t(image.width) * image.height * 3);
  for (size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      bytes[3 * i + c] = (unsigned char)unorm8(linearToSrgb(image.pixels[i][c] * exposure));
  writePngRgb(bytes, image.width, image.height, path);
}

void writePngRgb(const std::vector<unsigned char>& rgb, int width, int height, const std::string& path) {
  if (rgb.size() != size_t(width) * height * 3) throw Error("cannot write '" + path + "': the image has the wrong size");
  if (!stbi_write_png(path.c_str(), width, height, 3, rgb.data(), width * 3)) throw Error("cannot write '" + path + "'");
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
