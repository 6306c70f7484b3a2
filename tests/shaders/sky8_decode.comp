// Every sky8 code through the seed's decoder (shaders/common/sky8.glsl), so that
// tests hold the C++ twin (bake::decodeSky8Seed) to it bit for bit.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../../shaders/common/sky8.glsl"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push {
  uint first;  // the first code: r | g << 8 | b << 16
  uint count;
};
layout(std430, binding = 0) writeonly buffer Decoded { vec2 decoded[]; };
// byte / 255 correctly rounded, as a texture unit reads an 8-bit channel (a
// shader's own division may be 2.5 ulp off).
layout(std430, binding = 1) readonly buffer Unorm8 { float unorm8[256]; };

void main() {
  // Workgroups beyond the device's x limit continue along y (ComputeProgram).
  uint id = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
  if (id >= count) return;
  uint code = first + id;
  vec4 texel = vec4(unorm8[code & 255u], unorm8[(code >> 8) & 255u], unorm8[code >> 16], 1.0);
  decoded[id] = sky8Decode(texel);
}
