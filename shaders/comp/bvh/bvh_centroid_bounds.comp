// Build step 1: the bounds of primitive centroids per group, which the Morton
// codes are quantised in. Min and max are order-independent, so the result is
// the same whatever order the atomics land in.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "bvh_common.glsl"

layout(std430, binding = kBvhBindingPrimBoxes) readonly buffer PrimBoxes { float primBoxes[]; };
layout(std430, binding = kBvhBindingPrimGroups) readonly buffer PrimGroups { uint primGroups[]; };
layout(std430, binding = kBvhBindingGroups) buffer Groups { BvhGroup groups[]; };

void main() {
  uint i = threadIndex();
  if (i >= pc.count) return;
  uint g = pc.groupCount > 1u ? primGroups[i] : 0u;
  vec3 lo = vec3(primBoxes[6u * i], primBoxes[6u * i + 1u], primBoxes[6u * i + 2u]);
  vec3 hi = vec3(primBoxes[6u * i + 3u], primBoxes[6u * i + 4u], primBoxes[6u * i + 5u]);
  bool valid = all(lessThanEqual(lo, hi));
  vec3 c = 0.5 * (lo + hi);
  uvec3 keyLo = valid ? uvec3(orderedKey(c.x), orderedKey(c.y), orderedKey(c.z)) : uvec3(0xffffffffu);
  uvec3 keyHi = valid ? ~keyLo : uvec3(0xffffffffu);
  // Most subgroups hold one group's primitives: reduce there, one atomic each.
  bool uniformGroup = subgroupBallot(g == subgroupBroadcastFirst(g)) == subgroupBallot(true);
  if (uniformGroup) {
    keyLo = subgroupMin(keyLo);
    keyHi = subgroupMin(keyHi);
    if (!subgroupElect()) return;
  }
  if (keyLo.x == 0xffffffffu && keyHi.x == 0xffffffffu) return;
  for (uint k = 0u; k < 3u; ++k) {
    atomicMin(groups[g].centroidLo[k], keyLo[k]);
    atomicMin(groups[g].centroidHi[k], keyHi[k]);
  }
}
