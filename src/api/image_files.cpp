// Image files for hosts without an image library of their own (a pip
// install's snell-usd): decoded by stb_image, as the glTF loader decodes
// textures, and written as PNG by snell's own encoder (scene/png.h).
#include "snell/snell.h"

#include "scene/png.h"

#include <stb/stb_image.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <unistd.h>

namespace snell {

namespace fs = std::filesystem;

namespace {

std::vector<unsigned char> fileBytes(const std::string& path) {
  if (!fs::is_regular_file(path)) throw Error(path + ": no such file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open the file");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

uint8_t srgbByte(float linear) {
  float c = std::clamp(std::isnan(linear) ? 0.0f : linear, 0.0f, 1.0f);
  float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return static_cast<uint8_t>(std::lround(s * 255.0f));
}

}  // namespace

ImageFile readImageFile(const std::string& path) {
  std::vector<unsigned char> bytes = fileBytes(path);
  if (bytes.size() > size_t(INT32_MAX)) throw Error(path + ": the file is too large to decode");
  const auto* data = bytes.data();
  const int size = int(bytes.size());
  int width = 0, height = 0, channels = 0;
  if (!stbi_info_from_memory(data, size, &width, &height, &channels)) {
    throw Error(path + ": not an image snell decodes (" + stbi_failure_reason() +
                "; it reads PNG, JPEG, TGA, BMP, PSD, GIF, HDR, PIC and PNM)");
  }
  ImageFile image;
  uint32_t bits = stbi_is_hdr_from_memory(data, size) ? 32 : stbi_is_16_bit_from_memory(data, size) ? 16 : 8;
  std::unique_ptr<void, void (*)(void*)> pixels(nullptr, stbi_image_free);
  if (bits == 32) {
    pixels.reset(stbi_loadf_from_memory(data, size, &width, &height, &channels, 0));
  } else if (bits == 16) {
    pixels.reset(stbi_load_16_from_memory(data, size, &width, &height, &channels, 0));
  } else {
    pixels.reset(stbi_load_from_memory(data, size, &width, &height, &channels, 0));
  }
  if (!pixels) throw Error(path + ": cannot decode the image (" + stbi_failure_reason() + ")");
  image.width = uint32_t(width);
  image.height = uint32_t(height);
  image.channels = uint32_t(channels);
  image.bits = bits;
  image.data.resize(size_t(width) * size_t(height) * size_t(channels) * (bits / 8));
  std::memcpy(image.data.data(), pixels.get(), image.data.size());
  return image;
}

void writePng(const std::string& path, uint32_t width, uint32_t height, const float* rgba, bool alpha) {
  if (width == 0 || height == 0 || !rgba) throw Error(path + ": an image of " + std::to_string(width) + "x" +
                                                      std::to_string(height) + " pixels has nothing to write");
  fs::path target(path);
  fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(folder)) throw Error(path + ": the folder " + folder.string() + " does not exist");
  std::vector<uint8_t> bytes(size_t(width) * height * 4);
  for (size_t i = 0; i < size_t(width) * height; ++i) {
    for (size_t c = 0; c < 3; ++c) bytes[4 * i + c] = srgbByte(rgba[4 * i + c]);
    float a = std::clamp(std::isnan(rgba[4 * i + 3]) ? 0.0f : rgba[4 * i + 3], 0.0f, 1.0f);
    bytes[4 * i + 3] = alpha ? static_cast<uint8_t>(std::lround(a * 255.0f)) : 255;
  }
  std::vector<uint8_t> png = scene::encodePng(width, height, bytes);
  // The rename makes the write all-or-nothing: a file appears only once complete.
  fs::path temp = folder / ("." + target.stem().string() + ".partial-" + std::to_string(::getpid()) + ".png");
  {
    std::ofstream out(temp, std::ios::binary);
    out.write(reinterpret_cast<const char*>(png.data()), std::streamsize(png.size()));
    out.close();
    if (!out) {
      std::error_code ignored;
      fs::remove(temp, ignored);
      throw Error(path + ": could not write the file");
    }
  }
  std::error_code renamed;
  fs::rename(temp, target, renamed);
  if (renamed) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw Error(path + ": could not write the file (" + renamed.message() + ")");
  }
}

}  // namespace snell
