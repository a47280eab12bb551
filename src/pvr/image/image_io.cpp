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

Image readExr(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw Error("cannot read '" + path + "': no such file");
  try {
    Imf::RgbaInputFile file(path.c_str());
    const Imath::Box2i window = file.dataWindow();
    const long width = long(window.max.x) - window.min.x + 1, height = long(window.max.y) - window.min.y + 1;
    if (width <= 0 || height <= 0 || width > 65536 || height > 65536 || width * height > (1l << 28))
      throw Error("cannot read '" + path + "': unsupported image size " + std::to_string(width) + "x" + std::to_string(height));
    std::vector<Imf::Rgba> rgba(size_t(width) * size_t(height));
    file.setFrameBuffer(rgba.data() - window.min.x - window.min.y * width, 1, size_t(width));
    file.readPixels(window.min.y, window.max.y);
    Image image{static_cast<int>(width), static_cast<int>(height)};
    for (size_t i = 0; i < rgba.size(); ++i) image.pixels[i] = Vec3(float(rgba[i].r), float(rgba[i].g), float(rgba[i].b));
    return image;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    std::string what = e.what();
    throw Error("cannot read '" + path + "' as EXR: " + what.substr(0, what.find('\n')));
  }
}

void writeImage(const Image& image, const std::string& path, float exposure) {
  std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".png") writePng(image, path, exposure);
  else if (ext == ".exr") writeExr(image, path);
  else throw Error("unsupported image format '" + ext + "' for '" + path + "' (use .png or .exr)");
}

}  // namespace pvr
