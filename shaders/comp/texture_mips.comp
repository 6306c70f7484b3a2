// One mip level of a scene texture from the level above, both in one texel
// page: each texel the mean of the 2x2 block it covers (clamped at odd
// edges), averaged in linear light for colour textures (decoded through the
// sRGB table, encoded back and rounded to bytes) and as bytes for data
// textures. The reference builds the same chain in double (ref::mipChain).
// Bytes are averaged in integers, half up: a quarter of a data texture's means
// end in .5, which float arithmetic and GLSL's round() (its direction at .5 is
// the driver's) would tip either way, and a normal map one byte off bends a
// sharp highlight visibly (the broken window drew 0.3% of its pixels up to
// 93/255 off the reference, and differently on each driver).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../shared/trace.h"

layout(local_size_x = 64) in;
#include "../common/dispatch.glsl"
layout(push_constant) uniform Push { TextureMipPush pc; };
layout(std430, binding = 0) readonly buffer SrgbDecode { float srgbDecode[]; };
layout(std430, binding = 1) buffer Page { uint texels[]; };

float encodeSrgb(float c) {
  return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

void main() {
  uint id = invocationIndex();
  if (id >= pc.targetWidth * pc.targetHeight) return;
  uvec2 p = uvec2(id % pc.targetWidth, id / pc.targetWidth);
  uvec2 last = uvec2(pc.sourceWidth, pc.sourceHeight) - 1u;
  uvec4 byteSum = uvec4(0u);
  vec3 linearSum = vec3(0.0);
  for (uint j = 0u; j < 2u; ++j) {
    for (uint i = 0u; i < 2u; ++i) {
      uvec2 q = min(2u * p + uvec2(i, j), last);
      uint rgba = texels[pc.sourceFirst + q.y * pc.sourceWidth + q.x];
      uvec4 bytes = uvec4(rgba & 0xffu, (rgba >> 8) & 0xffu, (rgba >> 16) & 0xffu, rgba >> 24);
      byteSum += bytes;
      if (pc.srgb != 0u) linearSum += vec3(srgbDecode[bytes.r], srgbDecode[bytes.g], srgbDecode[bytes.b]);
    }
  }
  uvec4 bytes = (byteSum + 2u) / 4u;
  if (pc.srgb != 0u) {
    vec3 mean = linearSum * 0.25;
    vec3 encoded = vec3(encodeSrgb(mean.r), encodeSrgb(mean.g), encodeSrgb(mean.b));
    bytes.rgb = uvec3(floor(clamp(encoded, 0.0, 1.0) * 255.0 + 0.5));
  }
  texels[pc.targetFirst + id] = bytes.r | (bytes.g << 8) | (bytes.b << 16) | (bytes.a << 24);
}
