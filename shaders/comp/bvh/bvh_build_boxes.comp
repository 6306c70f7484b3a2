// Build step 1: one box per primitive of the build (triangles, or instances
// for the top level), packed entry after entry, and the bounds of their
// centroids per entry, which the Morton codes are quantised in. Min and max
// are order-independent, so the bounds are the same whatever order the
// atomics land in.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "bvh_common.glsl"

layout(std430, binding = kBvhBindingBuildEntries) buffer Entries { BvhBuildEntry entries[]; };
layout(std430, binding = kBvhBindingPositions) readonly buffer Positions { float positions[]; };
layout(std430, binding = kBvhBindingIndices) readonly buffer Indices { uint indices[]; };
layout(std430, binding = kBvhBindingInstances) readonly buffer Instances { GpuInstance instances[]; };
layout(std430, binding = kBvhBindingBlasGroups) readonly buffer BlasGroups { BvhGroup blasGroups[]; };
layout(std430, binding = kBvhBindingPrimBoxes) writeonly buffer PrimBoxes { float primBoxes[]; };
layout(std430, binding = kBvhBindingDropped) buffer Dropped { uint dropped; };
#include "bvh_leaves.glsl"

#include "bvh_entry_of.glsl"

void main() {
  uint t = invocationIndex();
  if (t >= pc.count) return;
  uint e = jobOf(t);
  uint prim = entries[e].first + (t - entries[e].base);
  vec3 lo, hi;
  primitiveBox(prim, lo, hi);
  for (uint k = 0u; k < 3u; ++k) {
    primBoxes[6u * t + k] = lo[k];
    primBoxes[6u * t + 3u + k] = hi[k];
  }
  bool valid = all(lessThanEqual(lo, hi));
  vec3 c = 0.5 * (lo + hi);
  uvec3 keyLo = valid ? uvec3(orderedKey(c.x), orderedKey(c.y), orderedKey(c.z)) : uvec3(0xffffffffu);
  uvec3 keyHi = valid ? ~keyLo : uvec3(0xffffffffu);
  // Most subgroups serve one entry: reduce there, one atomic each.
  if (subgroupBallot(e == subgroupBroadcastFirst(e)) == subgroupBallot(true)) {
    keyLo = subgroupMin(keyLo);
    keyHi = subgroupMin(keyHi);
    if (!subgroupElect()) return;
  }
  if (keyLo.x == 0xffffffffu && keyHi.x == 0xffffffffu) return;
  for (uint k = 0u; k < 3u; ++k) {
    atomicMin(entries[e].centroidLo[k], keyLo[k]);
    atomicMin(entries[e].centroidHi[k], keyHi[k]);
  }
}
