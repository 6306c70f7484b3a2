// PNG files' bytes, for the glTF writer's textures and the image and map files.
#pragma once

#include <cstdint>
#include <vector>

namespace snell::scene {

/// An RGBA8 image as a PNG file's bytes (filtered per row, deflated by zlib).
std::vector<uint8_t> encodePng(uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba);
/// A 16-bit RGBA image as a PNG file's bytes (filtered per row, deflated by zlib).
std::vector<uint8_t> encodePng16(uint32_t width, uint32_t height, const std::vector<uint16_t>& rgba);

}  // namespace snell::scene
