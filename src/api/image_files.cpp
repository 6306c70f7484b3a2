// Image files for hosts without an image library of their own (a pip
// install's snell-usd): decoded by stb_image, as the glTF loader decodes
// textures, and written as PNG by snell's own encoder (scene/png.h), whole
// or not at all (io/file_write.h).
#include "snell/snell.h"

#include "io/file_write.h"
#include "scene/png.h"

#include <stb/stb_image.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>

namespace snell {

namespace fs = std::filesystem;

namespace {

std::vector<unsigned char> fileBytes(const std::string& path) {
  if (!fs::is_regular_file(path)) throw Error(path + ": no such file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open the file");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
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
  std::vector<uint8_t> bytes(size_t(width) * height * 4);
  for (size_t i = 0; i < size_t(width) * height; ++i) {
    for (size_t c = 0; c < 3; ++c) bytes[4 * i + c] = io::linearToSrgb8(rgba[4 * i + c]);
    float a = std::clamp(std::isnan(rgba[4 * i + 3]) ? 0.0f : rgba[4 * i + 3], 0.0f, 1.0f);
    bytes[4 * i + 3] = alpha ? static_cast<uint8_t>(std::lround(a * 255.0f)) : 255;
  }
  std::vector<uint8_t> png = scene::encodePng(width, height, bytes);
  try {
    io::writeAtomically(path, [&](const std::string& temp) { io::writeBytes(path, temp, png); });
  } catch (const std::runtime_error& e) {
    throw Error(e.what());
  }
}

}  // namespace snell
