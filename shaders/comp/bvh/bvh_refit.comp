// The refit: new boxes for the trees of the groups listed, topology kept, in
// one dispatch whatever the number of groups. One invocation per node slot;
// those whose node holds a leaf box its primitive (a triangle, or an
// instance through its transform) into the node, and a node with two leaves
// is complete at once. Otherwise the invocation counts itself in at the node,
// as does the one coming up from the node's other child: the second arrival
// (an odd count: every refit adds two per such node, and a build starts it
// at zero) unites both slots and goes on up, writing the node's box into its
// parent. No invocation waits for another, and min/max make the boxes
// independent of arrival order. No leaf needs a parent link of its own.
//
// It also prices each tree with the surface area heuristic (Ct = Ci = 1), in
// fixed point against the root area of the group's last build, so the sum is
// exact whatever order the atomics land in: the host compares it with the
// sum just after the build to decide when a tree has degraded enough to rebuild.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_memory_scope_semantics : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "bvh_common.glsl"

layout(std430, binding = kBvhBindingRefitEntries) readonly buffer Entries { BvhRefitEntry entries[]; };
layout(std430, binding = kBvhBindingPositions) readonly buffer Positions { float positions[]; };
layout(std430, binding = kBvhBindingIndices) readonly buffer Indices { uint indices[]; };
layout(std430, binding = kBvhBindingInstances) readonly buffer Instances { GpuInstance instances[]; };
layout(std430, binding = kBvhBindingBlasGroups) readonly buffer BlasGroups { BvhGroup blasGroups[]; };
// Coherent: a box one invocation writes is read by another after the atomic.
layout(std430, binding = kBvhBindingNodes) coherent buffer Nodes { BvhNode nodes[]; };
layout(std430, binding = kBvhBindingGroups) buffer Groups { BvhGroup groups[]; };
layout(std430, binding = kBvhBindingStats) buffer Stats { uvec4 stats[]; };
layout(std430, binding = kBvhBindingDropped) buffer Dropped { uint dropped; };
#include "bvh_leaves.glsl"

uint entryOf(uint t) {
  uint lo = 0u, hi = pc.entryCount;
  while (hi - lo > 1u) {
    uint mid = (lo + hi) / 2u;
    if (entries[mid].threadBase <= t) lo = mid;
    else hi = mid;
  }
  return lo;
}

// A 64-bit add from two 32-bit atomics: the low word's carry is seen by the
// adder that caused it, and the high word's additions commute.
void addSah(uint g, uint lo, uint hi) {
  uint before = atomicAdd(stats[g].x, lo);
  if (before + lo < before) ++hi;
  if (hi != 0u) atomicAdd(stats[g].y, hi);
}

vec3 slotLo(uint node, uint slot) {
  return vec3(nodes[node].box[slot], nodes[node].box[slot + 1u], nodes[node].box[slot + 2u]);
}

vec3 slotHi(uint node, uint slot) {
  return vec3(nodes[node].box[slot + 3u], nodes[node].box[slot + 4u], nodes[node].box[slot + 5u]);
}

void writeSlot(uint node, uint slot, vec3 lo, vec3 hi) {
  for (uint k = 0u; k < 3u; ++k) {
    nodes[node].box[slot + k] = lo[k];
    nodes[node].box[slot + 3u + k] = hi[k];
  }
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

// Whether `node` is complete after this invocation's arrival (the second
// arrival is; a count is even between refits).
bool arrive(uint node) {
  // Release our box, acquire the sibling's: the atomic orders both.
  uint arrived = atomicAdd(nodes[node].arrivals, 1u, gl_ScopeDevice, gl_StorageSemanticsBuffer,
                           gl_SemanticsAcquireRelease);
  return (arrived & 1u) != 0u;
}

void main() {
  uint t = threadIndex();
  if (t >= pc.count) return;
  BvhRefitEntry entry = entries[entryOf(t)];
  uint g = entry.group;
  float unitScale = float(kBvhSahScale) / max(groups[g].buildArea, 1e-30);
  uint sah = 0u;
  vec3 lo, hi;
  bool climb = false;
  uint node = kBvhNone;

  if (entry.count == 1u) {  // one primitive: the root is its leaf
    primitiveBox(entry.first, lo, hi);
    writeGroupBox(g, lo, hi);
    sah = sahTerm(boxArea(lo, hi), unitScale);
  } else {
    node = entry.first + (t - entry.threadBase);
    uint children[2] = uint[2](nodes[node].child[0], nodes[node].child[1]);
    bool leaf0 = (children[0] & kBvhLeafBit) != 0u, leaf1 = (children[1] & kBvhLeafBit) != 0u;
    if (!leaf0 && !leaf1) return;  // its children's invocations come up to it
    for (uint c = 0u; c < 2u; ++c) {
      if ((children[c] & kBvhLeafBit) == 0u) continue;
      primitiveBox(children[c] & ~kBvhLeafBit, lo, hi);
      writeSlot(node, 6u * c, lo, hi);
      sah += sahTerm(boxArea(lo, hi), unitScale);
    }
    climb = (leaf0 && leaf1) || arrive(node);
  }

  for (uint step = 0u; climb && step < kBvhMaxDepth; ++step) {
    // `node` is complete: its box is the union of its slots.
    lo = min(slotLo(node, 0u), slotLo(node, 6u));
    hi = max(slotHi(node, 0u), slotHi(node, 6u));
    sah += sahTerm(boxArea(lo, hi), unitScale);
    uint parent = nodes[node].parent;
    if (parent == kBvhNone) {
      writeGroupBox(g, lo, hi);
      break;
    }
    uint slot = (parent & kBvhParentRight) != 0u ? 6u : 0u;
    parent &= ~kBvhParentRight;
    if (parent >= pc.total) break;  // a corrupted link: stop rather than write out of bounds
    writeSlot(parent, slot, lo, hi);
    node = parent;
    climb = arrive(node);
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
