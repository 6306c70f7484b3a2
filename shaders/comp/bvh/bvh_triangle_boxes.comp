// Bottom level, first step of a build or refit: one box per triangle. A
// triangle with a non-finite vertex gets an empty box, so it drops out of the
// tree instead of poisoning its ancestors' boxes, and is counted (a deform
// that produced NaN should be visible, not silently missing).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "bvh_common.glsl"

layout(std430, binding = kBvhBindingPositions) readonly buffer Positions { float positions[]; };
layout(std430, binding = kBvhBindingIndices) readonly buffer Indices { uint indices[]; };
layout(std430, binding = kBvhBindingPrimBoxes) writeonly buffer PrimBoxes { float primBoxes[]; };
layout(std430, binding = kBvhBindingDropped) buffer Dropped { uint dropped; };

vec3 vertex(uint v) {
  return vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
}

void main() {
  uint i = threadIndex();
  if (i >= pc.count) return;
  uint t = pc.first + i;
  vec3 a = vertex(indices[3u * t]), b = vertex(indices[3u * t + 1u]), c = vertex(indices[3u * t + 2u]);
  vec3 lo = min(a, min(b, c)), hi = max(a, max(b, c));
  if (!finite3(lo) || !finite3(hi)) {
    emptyBox(lo, hi);
    atomicAdd(dropped, 1u);
  }
  for (uint k = 0u; k < 3u; ++k) {
    primBoxes[6u * t + k] = lo[k];
    primBoxes[6u * t + 3u + k] = hi[k];
  }
}
