// Build step 2: a sort key per primitive, its build entry above a 30-bit
// Morton code of its centroid within the entry's centroid bounds, and the
// primitive as the value. Primitives with empty boxes sort last in their group.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "bvh_common.glsl"

layout(std430, binding = kBvhBindingBuildEntries) readonly buffer Entries { BvhBuildEntry entries[]; };
layout(std430, binding = kBvhBindingPrimBoxes) readonly buffer PrimBoxes { float primBoxes[]; };
layout(std430, binding = kBvhBindingKeys) writeonly buffer Keys { uint keys[]; };
layout(std430, binding = kBvhBindingValues) writeonly buffer Values { uint values[]; };

// Spreads the low 10 bits of v so two zero bits separate each.
uint spreadBits(uint v) {
  v &= 0x3ffu;
  v = (v | (v << 16)) & 0x030000ffu;
  v = (v | (v << 8)) & 0x0300f00fu;
  v = (v | (v << 4)) & 0x030c30c3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

#include "bvh_entry_of.glsl"

void main() {
  uint t = invocationIndex();
  if (t >= pc.count) return;
  uint e = jobOf(t);
  vec3 lo = vec3(primBoxes[6u * t], primBoxes[6u * t + 1u], primBoxes[6u * t + 2u]);
  vec3 hi = vec3(primBoxes[6u * t + 3u], primBoxes[6u * t + 4u], primBoxes[6u * t + 5u]);
  uint morton = (1u << kBvhMortonBits) - 1u;
  if (all(lessThanEqual(lo, hi))) {
    BvhBuildEntry entry = entries[e];
    vec3 cLo = vec3(orderedFloat(entry.centroidLo[0]), orderedFloat(entry.centroidLo[1]), orderedFloat(entry.centroidLo[2]));
    vec3 cHi = vec3(orderedFloat(~entry.centroidHi[0]), orderedFloat(~entry.centroidHi[1]), orderedFloat(~entry.centroidHi[2]));
    // One scale for all three axes (the bounds' largest extent): a flat or
    // thin group keeps its Morton order along the axes it spans, where
    // stretching each axis to 10 bits would let a sliver's noise lead.
    vec3 extent = cHi - cLo;
    float size = max(max(extent.x, extent.y), max(extent.z, 1e-30));
    vec3 unit = clamp((0.5 * (lo + hi) - cLo) / size, 0.0, 1.0);
    uvec3 q = uvec3(min(unit * 1024.0, vec3(1023.0)));
    morton = (spreadBits(q.x) << 2) | (spreadBits(q.y) << 1) | spreadBits(q.z);
  }
  if ((pc.flags & kBvhFlagKeys32) != 0u) {
    keys[t] = morton | (e << kBvhMortonBits);
  } else {
    keys[2u * t] = morton | (e << kBvhMortonBits);
    keys[2u * t + 1u] = e >> (32u - kBvhMortonBits);
  }
  values[t] = entries[e].first + (t - entries[e].base);
}
