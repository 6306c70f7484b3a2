#include "bake/refraction_map.h"

#include <algorithm>
#include <cmath>

namespace snell::bake {

namespace {

// One coordinate on the sky8 grid: x = 255 c / 16 in [0, 15.9375] splits
// into a tile (0-15) and the position inside it, red or green = round(255 frac).
// A position that rounds to 255 is the next tile's 0 (the same value): it is
// kept as 255 so that the tile never passes 15.
void encodeAxis(double c, uint8_t& tile, uint8_t& position) {
  double x = std::clamp(c, 0.0, 1.0) * 255.0 / 16.0;
  double t = std::min(std::floor(x), 15.0);
  tile = uint8_t(t);
  position = uint8_t(std::lround(std::clamp((x - t) * 255.0, 0.0, 255.0)));
}

}  // namespace

Sky8 encodeSky8(glm::dvec2 uv) {
  uint8_t tu = 0, tv = 0, r = 0, g = 0;
  encodeAxis(uv.x, tu, r);
  encodeAxis(uv.y, tv, g);
  return {r, g, uint8_t(tu << 4 | tv)};
}

glm::dvec2 decodeSky8(Sky8 code) {
  return {16.0 * (double(code.b >> 4) + double(code.r) / 255.0) / 255.0,
          16.0 * (double(code.b & 15) + double(code.g) / 255.0) / 255.0};
}

glm::vec2 decodeSky8Seed(Sky8 code) {
  // shaders/common/sky8.glsl line by line: divisions as products with 1/255
  // and 1/16, each float operation a separate rounded step (`volatile`: no
  // fused multiply-add, no wider intermediate). The bytes come in as a
  // texture unit reads them: byte / 255, correctly rounded.
  const float inv255 = 1.0f / 255.0f;
  volatile float r = float(code.r) / 255.0f, g = float(code.g) / 255.0f, b = float(code.b) / 255.0f;
  volatile float u = r * 16.0f;
  volatile float v = g * 16.0f;
  volatile float bu = b * 16.0f;
  volatile float tileU = std::floor(float(bu)) * 16.0f;
  u = u + tileU;
  volatile float b255 = b * 255.0f;
  volatile float whole = 16.0f * std::floor(float(b255) * 0.0625f);
  volatile float m = float(b255) - whole;  // mod(b * 255, 16)
  volatile float tileV = m * 16.0f;
  v = v + tileV;
  u = u * inv255;
  v = v * inv255;
  return {float(u), float(v)};
}

uint16_t encodeUnorm16(double x) { return uint16_t(std::lround(std::clamp(x, 0.0, 1.0) * 65535.0)); }

uint8_t encodeUnorm8(double x) { return uint8_t(std::lround(std::clamp(x, 0.0, 1.0) * 255.0)); }

}  // namespace snell::bake
