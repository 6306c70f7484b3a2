// Build step 5 (6 after a restructuring): each node of the groups just built
// gets its children's boxes in the form the trace reads, from the exact
// boxes of the build (a leaf's primitive box, an inner child's box as H-PLOC
// or the restructuring left it in the exact boxes): kept exact beside the
// node (shared/bvh.h), or, in a compact forest, quantised within the node's
// own box (BvhNode). Either way the node's refit arrivals start cleared. A
// pass of its own, one invocation per node: in H-PLOC each merge's
// quantisation held up the whole team at its next barrier. The nodes are the
// same, bit for bit, as a quantisation inside the merge made them: the same
// exact boxes go in.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "bvh_common.glsl"
#include "bvh_node.glsl"

layout(std430, binding = kBvhBindingBuildEntries) readonly buffer Entries { BvhBuildEntry entries[]; };
layout(std430, binding = kBvhBindingPrimBoxes) readonly buffer PrimBoxes { float primBoxes[]; };
layout(std430, binding = kBvhBindingExactBoxes) readonly buffer ExactBoxes { float exact[]; };
layout(std430, binding = kBvhBindingNodes) buffer Nodes { BvhNode nodes[]; };
layout(std430, binding = kBvhBindingChildBoxes) writeonly buffer ChildBoxes { vec4 childBoxes[]; };
layout(std430, binding = kBvhBindingWideRecords) writeonly buffer WideRecords { vec4 wideRecords[]; };

#include "bvh_entry_of.glsl"
#include "bvh_wide_record.glsl"

#include "bvh_child_box.glsl"

void main() {
  uint t = invocationIndex();
  if (t >= pc.count) return;
  BvhBuildEntry entry = entries[jobOf(t)];
  uint local = t - entry.base;
  if (local + 1u >= entry.count) return;  // a group of n leaves has n - 1 nodes
  uint node = entry.first + local;
  BvhNode n = nodes[node];
  vec3 lo0, hi0, lo1, hi1;
  childBox(entry, n.child[0], lo0, hi0);
  childBox(entry, n.child[1], lo1, hi1);
  if ((pc.flags & kBvhFlagChildBoxes) != 0u) {  // the trace reads these, not the node's quantised boxes
    packChildBoxes(lo0, hi0, lo1, hi1, childBoxes[3u * node], childBoxes[3u * node + 1u], childBoxes[3u * node + 2u]);
    writeWideShare(node, n.parent, lo0, hi0, lo1, hi1, n.child[0], n.child[1]);
    nodes[node].scale = 0u;
    return;
  }
  encodeNode(n, lo0, hi0, lo1, hi1);
  nodes[node].origin = n.origin;
  nodes[node].scale = n.scale;
  nodes[node].quant = n.quant;
}
