// Build step 5, and the whole of a refit: boxes from the leaves up. Each leaf
// writes its box into its parent's slot and counts itself in; the second
// arrival at a node owns it (the first stops), unites both slots and goes on
// up. No invocation waits for another, so it is safe without forward-progress
// guarantees, and min/max make the boxes independent of arrival order.
// The host runs it with one subgroup per workgroup: lavapipe lost boxes
// passed between subgroups of one workgroup this way (tests/bvh_test.cpp).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_memory_scope_semantics : require
#include "bvh_common.glsl"

layout(std430, binding = kBvhBindingPrimBoxes) readonly buffer PrimBoxes { float primBoxes[]; };
layout(std430, binding = kBvhBindingPrimGroups) readonly buffer PrimGroups { uint primGroups[]; };
layout(std430, binding = kBvhBindingLeafPrims) readonly buffer LeafPrims { uint leafPrims[]; };
layout(std430, binding = kBvhBindingLeafParents) readonly buffer LeafParents { uint leafParents[]; };
// Coherent: a box one invocation writes is read by another after the atomic.
layout(std430, binding = kBvhBindingNodes) coherent buffer Nodes { BvhNode nodes[]; };
// Zeroed before every fit by the host. (Resetting them here, after the second
// arrival, lost arrivals on lavapipe: a store after a divergent break.)
layout(std430, binding = kBvhBindingCounters) coherent buffer Counters { uint counters[]; };
layout(std430, binding = kBvhBindingGroups) buffer Groups { BvhGroup groups[]; };

void main() {
  uint i = threadIndex();
  if (i >= pc.count) return;
  uint leaf = pc.first + i;
  uint prim = leafPrims[leaf];
  vec3 lo = vec3(primBoxes[6u * prim], primBoxes[6u * prim + 1u], primBoxes[6u * prim + 2u]);
  vec3 hi = vec3(primBoxes[6u * prim + 3u], primBoxes[6u * prim + 4u], primBoxes[6u * prim + 5u]);
  uint ref = kBvhLeafBit | prim;
  uint parent = leafParents[prim];
  uint internalCount = pc.total - 1u;

  for (uint step = 0u; step < kBvhMaxDepth; ++step) {
    if (parent == kBvhNone) {
      uint g = pc.groupCount > 1u ? primGroups[prim] : 0u;
      for (uint k = 0u; k < 3u; ++k) {
        groups[g].boxLo[k] = lo[k];
        groups[g].boxHi[k] = hi[k];
      }
      break;
    }
    if (parent >= internalCount) break;  // a corrupted link: stop rather than write out of bounds
    uint slot = nodes[parent].child[0] == ref ? 0u : 6u;
    for (uint k = 0u; k < 3u; ++k) {
      nodes[parent].box[slot + k] = lo[k];
      nodes[parent].box[slot + 3u + k] = hi[k];
    }
    // Release our box, acquire the sibling's: the atomic orders both.
    uint arrived = atomicAdd(counters[parent], 1u, gl_ScopeDevice, gl_StorageSemanticsBuffer, gl_SemanticsAcquireRelease);
    if (arrived == 0u) break;  // the sibling's box is not there yet
    uint other = 6u - slot;
    vec3 otherLo = vec3(nodes[parent].box[other], nodes[parent].box[other + 1u], nodes[parent].box[other + 2u]);
    vec3 otherHi = vec3(nodes[parent].box[other + 3u], nodes[parent].box[other + 4u], nodes[parent].box[other + 5u]);
    lo = min(lo, otherLo);
    hi = max(hi, otherHi);
    ref = parent;
    parent = nodes[parent].parent;
  }
}
