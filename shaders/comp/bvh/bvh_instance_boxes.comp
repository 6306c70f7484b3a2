// Top level, first step: one world box per instance, its bottom-level root
// box carried through the instance transform (Arvo's method: centre moved,
// extent through the absolute matrix). Instances of empty shapes get empty boxes.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "bvh_common.glsl"
#include "../../shared/trace.h"

layout(std430, binding = kBvhBindingInstances) readonly buffer Instances { GpuInstance instances[]; };
layout(std430, binding = kBvhBindingBlasGroups) readonly buffer BlasGroups { BvhGroup blasGroups[]; };
layout(std430, binding = kBvhBindingPrimBoxes) writeonly buffer PrimBoxes { float primBoxes[]; };

void main() {
  uint i = threadIndex();
  if (i >= pc.count) return;
  GpuInstance inst = instances[i];
  BvhGroup g = blasGroups[inst.geometry];
  vec3 lo = vec3(g.boxLo[0], g.boxLo[1], g.boxLo[2]);
  vec3 hi = vec3(g.boxHi[0], g.boxHi[1], g.boxHi[2]);
  if (g.root == kBvhNone || !all(lessThanEqual(lo, hi))) {
    emptyBox(lo, hi);
  } else {
    vec3 centre = 0.5 * (lo + hi), extent = 0.5 * (hi - lo);
    vec3 c, e;
    for (uint r = 0u; r < 3u; ++r) {
      vec4 row = inst.objectToWorld[r];
      c[r] = dot(row.xyz, centre) + row.w;
      e[r] = dot(abs(row.xyz), extent);
    }
    lo = c - e;
    hi = c + e;
    if (!finite3(lo) || !finite3(hi)) emptyBox(lo, hi);
  }
  for (uint k = 0u; k < 3u; ++k) {
    primBoxes[6u * i + k] = lo[k];
    primBoxes[6u * i + 3u + k] = hi[k];
  }
}
