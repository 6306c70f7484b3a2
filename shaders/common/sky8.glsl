// The sky8 refraction map's decoder, as the seed's GLSL writes it (the Sky
// paper, ../shared/seeds, "GLSL Code"): `normal` is the map's texel with each
// 8-bit channel read as byte / 255. Kept verbatim, its quirk included: blue
// 255 reads as u's tile 16, not 15. (Its mod(b * 255, 16) could have misread
// a b * 255 rounded just under a whole number; in 32-bit float none is.)
// src/bake/refraction_map.h has it in C++ (decodeSky8Seed) and the exact
// inverse of snell's encoder.
#ifndef SNELL_SKY8_GLSL
#define SNELL_SKY8_GLSL

vec2 sky8Decode(vec4 normal) {
  precise float u = normal.r * 16.0;
  precise float v = normal.g * 16.0;
  u += floor(normal.b * 16.0) * 16.0;
  v += mod(normal.b * 255.0, 16.0) * 16.0;
  u = u / 255.0;
  v = v / 255.0;
  return vec2(u, v);
}

#endif
