// Refraction maps (issue 16; the Sky paper, ../shared/seeds, chapters 3-4):
// per pixel, the UV behind the glass that the pixel shows, stored as
//   rg16: 16-bit red and green, UV = value / 65535;
//   exr:  32-bit float red and green, the UV itself;
//   sky8: 8-bit RGB, the seed's "pseudo high colour depth": a UV gradient
//         tiled 16 x 16 times, blue the tile (high nibble: u's tile, low
//         nibble: v's), red and green the position inside it.
// sky8 is defined by the seed's GLSL decoder, which reads 16 tiles of
// 16/255 each, so the map addresses UV in [0, 256/255]:
//   u = (16 R/255 + 16 floor(16 B/255)) / 255,  v = (16 G/255 + 16 mod(B, 16)) / 255.
// encodeSky8 places UV on that grid (steps of 16/255^2, about 1/4064);
// decodeSky8 is its exact inverse; decodeSky8Seed is the seed's GLSL in float,
// its quirk included: blue 255 reads as u's tile 16, not 15. Over all 2^24
// codes the two agree within float rounding except on those 65536, where u
// is 16/255 apart (docs/refraction-maps.md).
#pragma once

#include <glm/glm.hpp>

#include <cstdint>

namespace snell::bake {

struct Sky8 {
  uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Sky8&) const = default;
};

/// The sky8 code nearest to `uv` (each coordinate clamped to [0, 1]) that
/// decodeSky8 reads back exactly.
Sky8 encodeSky8(glm::dvec2 uv);

/// The exact inverse of encodeSky8: u = 16 (tile + R/255) / 255 with the tile
/// the blue byte's high nibble (v: green and the low nibble).
glm::dvec2 decodeSky8(Sky8 code);

/// The seed's GLSL decoder as shaders/common/sky8.glsl keeps it, operation
/// for operation in float (as a desktop GPU runs its mediump), the bytes
/// first normalised to byte / 255 (correctly rounded, as a texture unit
/// reads them), its divisions as products (so that every conforming GPU
/// computes the same bits; a shader's division may be 2.5 ulp off).
glm::vec2 decodeSky8Seed(Sky8 code);

/// 16-bit unsigned normalised: round(clamp(x, 0, 1) * 65535).
uint16_t encodeUnorm16(double x);
inline double decodeUnorm16(uint16_t value) { return double(value) / 65535.0; }

/// Plain 8-bit, for comparison: round(clamp(x, 0, 1) * 255).
uint8_t encodeUnorm8(double x);
inline double decodeUnorm8(uint8_t value) { return double(value) / 255.0; }

}  // namespace snell::bake
