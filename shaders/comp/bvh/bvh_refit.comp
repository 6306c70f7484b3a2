// The refit: new boxes for the trees of the groups listed, topology kept, in
// one dispatch whatever the number of groups. One invocation per node slot;
// those whose node holds a leaf box its primitive (a triangle, or an
// instance through its transform), and a node with two leaves is complete at
// once. Otherwise the invocation counts itself in at the node, as does the
// one coming up from the node's other child: the second arrival (the node's
// arrival bit was set: every refit flips it twice, a build clears it)
// finishes the node and goes on up. No invocation waits for another.
//
// A node's children's boxes are known once both children are, so exact
// boxes travel through a scratch array: a node's own once it is complete,
// and a half-leaf node's leaf box meanwhile. min/max make every box
// independent of arrival order. A complete node keeps its children's exact
// boxes beside it for the trace (shared/bvh.h), or, in a compact forest,
// stores them quantised within its own box, which depends on nothing else.
//
// It also prices each tree with the surface area heuristic (Ct = Ci = 1,
// exact boxes), in fixed point against the root area of the group's last
// build, so the sum is exact whatever order the atomics land in: the host
// compares it with the sum just after the build to decide when a tree has
// degraded enough to rebuild.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_memory_scope_semantics : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "bvh_common.glsl"
#include "bvh_node.glsl"

layout(std430, binding = kBvhBindingRefitEntries) readonly buffer Entries { BvhRefitEntry entries[]; };
layout(std430, binding = kBvhBindingPositions) readonly buffer Positions { float positions[]; };
layout(std430, binding = kBvhBindingIndices) readonly buffer Indices { uint indices[]; };
layout(std430, binding = kBvhBindingInstances) readonly buffer Instances { GpuInstance instances[]; };
layout(std430, binding = kBvhBindingBlasGroups) readonly buffer BlasGroups { BvhGroup blasGroups[]; };
// Coherent: what one invocation writes is read by another after the atomic.
layout(std430, binding = kBvhBindingNodes) coherent buffer Nodes { BvhNode nodes[]; };
layout(std430, binding = kBvhBindingExactBoxes) coherent buffer ExactBoxes { float exact[]; };
layout(std430, binding = kBvhBindingChildBoxes) writeonly buffer ChildBoxes { vec4 childBoxes[]; };
layout(std430, binding = kBvhBindingWideRecords) writeonly buffer WideRecords { vec4 wideRecords[]; };
layout(std430, binding = kBvhBindingGroups) buffer Groups { BvhGroup groups[]; };
layout(std430, binding = kBvhBindingStats) buffer Stats { uvec4 stats[]; };
layout(std430, binding = kBvhBindingDropped) buffer Dropped { uint dropped; };
#include "bvh_leaves.glsl"

#define JOB_FIRST(i) entries[i].threadBase
#include "bvh_entry_of.glsl"
#include "bvh_wide_record.glsl"

// A 64-bit add from two 32-bit atomics: the low word's carry is seen by the
// adder that caused it, and the high word's additions commute.
void addSah(uint g, uint lo, uint hi) {
  uint before = atomicAdd(stats[g].x, lo);
  if (before + lo < before) ++hi;
  if (hi != 0u) atomicAdd(stats[g].y, hi);
}

void writeExact(uint node, vec3 lo, vec3 hi) {
  for (uint k = 0u; k < 3u; ++k) {
    exact[6u * node + k] = lo[k];
    exact[6u * node + 3u + k] = hi[k];
  }
}

void readExact(uint node, out vec3 lo, out vec3 hi) {
  lo = vec3(exact[6u * node], exact[6u * node + 1u], exact[6u * node + 2u]);
  hi = vec3(exact[6u * node + 3u], exact[6u * node + 4u], exact[6u * node + 5u]);
}

// The root's new box, and its area next to the build's for the host's SAH ratio.
void writeGroupBox(uint g, vec3 lo, vec3 hi) {
  for (uint k = 0u; k < 3u; ++k) {
    groups[g].boxLo[k] = lo[k];
    groups[g].boxHi[k] = hi[k];
  }
  stats[g].z = floatBitsToUint(boxArea(lo, hi));
  stats[g].w = floatBitsToUint(groups[g].buildArea);
}

// Whether `node` is complete after this invocation's arrival: the second
// arrival finds the bit the first one set. Release what this invocation
// wrote, acquire what the other did.
bool arrive(uint node) {
  uint before = atomicXor(nodes[node].scale, kBvhArrivalBit, gl_ScopeDevice, gl_StorageSemanticsBuffer,
                          gl_SemanticsAcquireRelease);
  return (before & kBvhArrivalBit) != 0u;
}

void main() {
  uint t = invocationIndex();
  if (t >= pc.count) return;
  BvhRefitEntry entry = entries[jobOf(t)];
  uint g = entry.group;
  float unitScale = float(kBvhSahScale) / max(groups[g].buildArea, 1e-30);
  uint sah = 0u;
  vec3 lo, hi;

  if (entry.count == 1u) {  // one primitive: the root is its leaf
    primitiveBox(entry.first, lo, hi);
    writeGroupBox(g, lo, hi);
    sah = sahTerm(boxArea(lo, hi), unitScale);
  } else {
    uint node = entry.first + (t - entry.threadBase);
    uint children[2] = uint[2](nodes[node].child[0], nodes[node].child[1]);
    bool leaf0 = (children[0] & kBvhLeafBit) != 0u, leaf1 = (children[1] & kBvhLeafBit) != 0u;
    if (!leaf0 && !leaf1) return;  // its children's invocations come up to it
    vec3 childLo[2], childHi[2];
    for (uint c = 0u; c < 2u; ++c) {
      if ((children[c] & kBvhLeafBit) == 0u) continue;
      primitiveBox(children[c] & ~kBvhLeafBit, childLo[c], childHi[c]);
      sah += sahTerm(boxArea(childLo[c], childHi[c]), unitScale);
    }
    bool complete = leaf0 && leaf1;
    if (!complete) {
      // Half-leaf: the leaf's box waits in the node's exact box for the other child.
      uint leafSide = leaf0 ? 0u : 1u;
      writeExact(node, childLo[leafSide], childHi[leafSide]);
      complete = arrive(node);
      if (complete) readExact(children[1u - leafSide], childLo[1u - leafSide], childHi[1u - leafSide]);
    }
    for (uint step = 0u; complete && step < kBvhMaxDepth; ++step) {
      // `node` is complete: store its children's boxes, then hand its exact box up.
      uint parent = nodes[node].parent;
      if ((pc.flags & kBvhFlagChildBoxes) != 0u) {
        packChildBoxes(childLo[0], childHi[0], childLo[1], childHi[1], childBoxes[3u * node], childBoxes[3u * node + 1u],
                       childBoxes[3u * node + 2u]);
        writeWideShare(node, parent, childLo[0], childHi[0], childLo[1], childHi[1], nodes[node].child[0],
                       nodes[node].child[1]);
      } else {
        BvhNode n = nodes[node];
        encodeNode(n, childLo[0], childHi[0], childLo[1], childHi[1]);
        nodes[node].origin = n.origin;
        nodes[node].quant = n.quant;
        nodes[node].scale = n.scale;
      }
      lo = min(childLo[0], childLo[1]);
      hi = max(childHi[0], childHi[1]);
      sah += sahTerm(boxArea(lo, hi), unitScale);
      if (parent == kBvhNone) {
        writeGroupBox(g, lo, hi);
        break;
      }
      uint side = (parent & kBvhParentRight) != 0u ? 1u : 0u;
      parent &= ~kBvhParentRight;
      if (parent >= pc.total) break;  // a corrupted link: stop rather than write out of bounds
      writeExact(node, lo, hi);
      childLo[side] = lo;
      childHi[side] = hi;
      complete = arrive(parent);
      if (!complete) break;
      // The sibling: a leaf's box waits in the parent's exact box, a node's in its own.
      uint sibling = nodes[parent].child[1u - side];
      readExact((sibling & kBvhLeafBit) != 0u ? parent : sibling, childLo[1u - side], childHi[1u - side]);
      node = parent;
    }
  }

  // One pair of atomics per subgroup where it serves one group. Each
  // invocation's sum is below 2^30, so its 16-bit halves add without overflow.
  if (subgroupBallot(g == subgroupBroadcastFirst(g)) == subgroupBallot(true)) {
    uint low = subgroupAdd(sah & 0xffffu), high = subgroupAdd(sah >> 16);
    if (!subgroupElect()) return;
    uint sumLo = low + (high << 16);
    addSah(g, sumLo, (high >> 16) + (sumLo < low ? 1u : 0u));
  } else {
    addSah(g, sah, 0u);
  }
}
