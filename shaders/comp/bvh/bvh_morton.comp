// Build step 2: a 64-bit sort key per primitive, its group above a 30-bit
// Morton code of its centroid within the group's centroid bounds. Primitives
// with empty boxes sort last in their group.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "bvh_common.glsl"

layout(std430, binding = kBvhBindingPrimBoxes) readonly buffer PrimBoxes { float primBoxes[]; };
layout(std430, binding = kBvhBindingPrimGroups) readonly buffer PrimGroups { uint primGroups[]; };
layout(std430, binding = kBvhBindingGroups) readonly buffer Groups { BvhGroup groups[]; };
layout(std430, binding = kBvhBindingKeys) writeonly buffer Keys { uvec2 keys[]; };
layout(std430, binding = kBvhBindingLeafPrims) writeonly buffer LeafPrims { uint leafPrims[]; };

// Spreads the low 10 bits of v so two zero bits separate each.
uint spreadBits(uint v) {
  v &= 0x3ffu;
  v = (v | (v << 16)) & 0x030000ffu;
  v = (v | (v << 8)) & 0x0300f00fu;
  v = (v | (v << 4)) & 0x030c30c3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

void main() {
  uint i = threadIndex();
  if (i >= pc.count) return;
  uint g = pc.groupCount > 1u ? primGroups[i] : 0u;
  vec3 lo = vec3(primBoxes[6u * i], primBoxes[6u * i + 1u], primBoxes[6u * i + 2u]);
  vec3 hi = vec3(primBoxes[6u * i + 3u], primBoxes[6u * i + 4u], primBoxes[6u * i + 5u]);
  uint morton = (1u << kBvhMortonBits) - 1u;
  if (all(lessThanEqual(lo, hi))) {
    BvhGroup grp = groups[g];
    vec3 cLo = vec3(orderedFloat(grp.centroidLo[0]), orderedFloat(grp.centroidLo[1]), orderedFloat(grp.centroidLo[2]));
    vec3 cHi = vec3(orderedFloat(~grp.centroidHi[0]), orderedFloat(~grp.centroidHi[1]), orderedFloat(~grp.centroidHi[2]));
    vec3 extent = cHi - cLo;
    vec3 unit = clamp((0.5 * (lo + hi) - cLo) / max(extent, vec3(1e-30)), 0.0, 1.0);
    uvec3 q = uvec3(min(unit * 1024.0, vec3(1023.0)));
    morton = (spreadBits(q.x) << 2) | (spreadBits(q.y) << 1) | spreadBits(q.z);
  }
  keys[i] = uvec2(morton | (g << kBvhMortonBits), g >> (32u - kBvhMortonBits));
  leafPrims[i] = i;
}
