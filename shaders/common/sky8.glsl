// The sky8 refraction map's decoder, as the seed's GLSL writes it (the Sky
// paper, ../shared/seeds, "GLSL Code"): `normal` is the map's texel with each
// 8-bit channel read as byte / 255. Kept in behaviour, its quirk included: blue
// 255 reads as u's tile 16, not 15. (Its mod(b * 255, 16) could have misread
// a b * 255 rounded just under a whole number; in 32-bit float none is.)
// src/bake/refraction_map.h has it in C++ (decodeSky8Seed) and the exact
// inverse of snell's encoder.
#ifndef SNELL_SKY8_GLSL
#define SNELL_SKY8_GLSL

// Divisions are written as products with 1/255 and 1/16: Vulkan lets a
// division be 2.5 ulp off, and NVIDIA's is, while products are correctly
// rounded everywhere; `precise` keeps each product its own rounded step. So
// every conforming GPU and the C++ twin compute the same bits.
const float kInv255 = 1.0 / 255.0;

vec2 sky8Decode(vec4 normal) {
  precise float u = normal.r * 16.0;
  precise float v = normal.g * 16.0;
  u += floor(normal.b * 16.0) * 16.0;
  precise float b255 = normal.b * 255.0;
  v += (b255 - 16.0 * floor(b255 * 0.0625)) * 16.0;  // mod(normal.b * 255.0, 16.0)
  u = u * kInv255;
  v = v * kInv255;
  return vec2(u, v);
}

#endif
