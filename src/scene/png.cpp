// PNG files' bytes: 8-bit RGBA through stb's encoder, 16-bit RGBA filtered
// here and deflated by stb (stb writes only 8-bit samples).
#include "scene/png.h"

#include <stb/stb_image_write.h>

#include <array>
#include <cstdlib>
#include <stdexcept>
#include <string>

// Debian's libstb exports stb's deflate but its header declares it only in the implementation part.
extern "C" unsigned char* stbi_zlib_compress(unsigned char* data, int data_len, int* out_len, int quality);

namespace snell::scene {

namespace {

uint32_t crc32(const uint8_t* data, size_t n, uint32_t crc = 0) {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  crc = ~crc;
  for (size_t i = 0; i < n; ++i) crc = table[(crc ^ data[i]) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

void putBigEndian(std::vector<uint8_t>& out, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<uint8_t>(v >> s));
}

void chunk(std::vector<uint8_t>& png, const char* type, const std::vector<uint8_t>& data) {
  putBigEndian(png, static_cast<uint32_t>(data.size()));
  size_t start = png.size();
  png.insert(png.end(), type, type + 4);
  png.insert(png.end(), data.begin(), data.end());
  putBigEndian(png, crc32(png.data() + start, png.size() - start));
}

}  // namespace

std::vector<uint8_t> encodePng(uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba) {
  if (rgba.size() != size_t(width) * height * 4) throw std::invalid_argument("encodePng: pixels do not fill the image");
  // stb picks a filter per row and deflates: a frame is a tenth of its bytes stored.
  std::vector<uint8_t> png;
  auto append = [](void* context, void* data, int size) {
    auto* out = static_cast<std::vector<uint8_t>*>(context);
    out->insert(out->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
  };
  if (!stbi_write_png_to_func(append, &png, int(width), int(height), 4, rgba.data(), int(width * 4))) {
    throw std::runtime_error("encodePng: stb could not encode a " + std::to_string(width) + "x" + std::to_string(height) + " image");
  }
  return png;
}

std::vector<uint8_t> encodePng16(uint32_t width, uint32_t height, const std::vector<uint16_t>& rgba) {
  if (rgba.size() != size_t(width) * height * 4) throw std::invalid_argument("encodePng16: pixels do not fill the image");
  // Each row big-endian, then filtered as PNG allows (none, sub or up: the
  // one with the smallest sum, as stb and libpng choose), then deflated.
  const size_t rowBytes = size_t(width) * 8;
  std::vector<uint8_t> previous(rowBytes, 0), row(rowBytes), best, candidate(rowBytes);
  std::vector<uint8_t> raw;
  raw.reserve(size_t(height) * (rowBytes + 1));
  for (uint32_t y = 0; y < height; ++y) {
    for (size_t i = 0; i < size_t(width) * 4; ++i) {
      uint16_t v = rgba[size_t(y) * width * 4 + i];
      row[2 * i] = uint8_t(v >> 8);
      row[2 * i + 1] = uint8_t(v);
    }
    uint8_t bestFilter = 0;
    uint64_t bestSum = UINT64_MAX;
    for (uint8_t filter = 0; filter < 3; ++filter) {
      uint64_t sum = 0;
      for (size_t i = 0; i < rowBytes; ++i) {
        uint8_t left = i >= 8 ? row[i - 8] : 0;
        candidate[i] = uint8_t(row[i] - (filter == 1 ? left : filter == 2 ? previous[i] : 0));
        sum += uint64_t(std::abs(int(int8_t(candidate[i]))));
      }
      if (sum < bestSum) bestSum = sum, bestFilter = filter, best = candidate;
    }
    raw.push_back(bestFilter);
    raw.insert(raw.end(), best.begin(), best.end());
    std::swap(previous, row);
  }
  int zlibBytes = 0;
  unsigned char* deflated = stbi_zlib_compress(raw.data(), int(raw.size()), &zlibBytes, stbi_write_png_compression_level);
  if (!deflated) throw std::runtime_error("encodePng16: stb could not deflate a " + std::to_string(width) + "x" + std::to_string(height) + " image");
  std::vector<uint8_t> zlib(deflated, deflated + zlibBytes);
  std::free(deflated);
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  std::vector<uint8_t> header;
  putBigEndian(header, width);
  putBigEndian(header, height);
  header.insert(header.end(), {16, 6, 0, 0, 0});  // 16-bit RGBA, no interlace
  chunk(png, "IHDR", header);
  chunk(png, "IDAT", zlib);
  chunk(png, "IEND", {});
  return png;
}

}  // namespace snell::scene
