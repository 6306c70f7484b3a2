// Optional build step 5, run a few rounds after H-PLOC: treelet restructuring
// (Karras & Aila 2013, "Fast parallel construction of high-quality bounding
// volume hierarchies"). H-PLOC only clusters within a window along the Morton
// order; this pass walks the tree bottom-up as the refit does and, at every
// node with enough leaves below it, grows a treelet of
// up to kTreeletLeaves subtrees (always opening the largest), finds the
// cheapest binary tree over them by dynamic programming over their subsets,
// and rewires the treelet's own internal nodes into that tree. One invocation
// owns one treelet; the subtrees below a node are final before its second
// arrival (acquire/release on the counters), so no two treelets overlap and the
// result does not depend on which invocation got where first.
//
// Cost of a subtree (one primitive per leaf, Ct = Ci = 1, the measure of
// src/ref/sah_bvh.h times the root's area): a leaf costs its box's area, an
// internal node its area plus its children's costs. Boxes of the rewired
// nodes are unions of the same leaf boxes the build used, so they stay exact.
// It works on H-PLOC's links and exact boxes, before the quantisation.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_memory_scope_semantics : require
#include "bvh_common.glsl"

layout(std430, binding = kBvhBindingBuildEntries) readonly buffer Entries { BvhBuildEntry entries[]; };
layout(std430, binding = kBvhBindingNodes) coherent buffer Nodes { BvhNode nodes[]; };
layout(std430, binding = kBvhBindingPrimBoxes) readonly buffer PrimBoxes { float primBoxes[]; };
layout(std430, binding = kBvhBindingExactBoxes) coherent buffer ExactBoxes { float exact[]; };
layout(std430, binding = kBvhBindingCounters) coherent buffer Counters { uint counters[]; };
// Per internal node: its subtree's cost (float bits) and leaf count.
layout(std430, binding = kBvhBindingNodeStats) coherent buffer NodeStats { uvec2 nodeStats[]; };

// Five, not the paper's seven: on the H200 seven cut the SAH ratio of the
// worst sample mesh from 1.23 to 1.17 but made the eye-256 build 20.6 ms
// instead of 3.6 ms, because one invocation does a whole treelet's subset
// search (the paper spreads it over a warp).
const uint kTreeletLeaves = 5u;
const uint kSubsets = 1u << kTreeletLeaves;
const uint kTreeletInternal = kTreeletLeaves - 1u;
// A treelet is only rebuilt when that saves more than rounding could fake.
const float kMinGain = 1e-5;

BvhBuildEntry entry;  // the group of the invocation's tree

#include "bvh_child_box.glsl"

// The treelet under construction: its leaves (subtrees kept whole) and the
// internal nodes it opened, whose indices the new tree reuses.
uint leafRef[kTreeletLeaves];
vec3 leafLo[kTreeletLeaves], leafHi[kTreeletLeaves];
uint internalNode[kTreeletInternal];
// Dynamic programming over subsets of the treelet's leaves.
vec3 subsetLo[kSubsets], subsetHi[kSubsets];
float subsetCost[kSubsets];
uint subsetSplit[kSubsets];

float refCost(uint ref, vec3 lo, vec3 hi) {
  return (ref & kBvhLeafBit) != 0u ? boxArea(lo, hi) : uintBitsToFloat(nodeStats[ref].x);
}

uint refLeaves(uint ref) {
  return (ref & kBvhLeafBit) != 0u ? 1u : nodeStats[ref].y;
}

// Grows the treelet at `root`; returns its leaf count and the cost of the tree as it is.
uint formTreelet(uint root, out float currentCost) {
  internalNode[0] = root;
  uint internals = 1u;
  for (uint c = 0u; c < 2u; ++c) {
    leafRef[c] = nodes[root].child[c];
    childBox(entry, nodes[root].child[c], leafLo[c], leafHi[c]);
  }
  vec3 rootLo = min(leafLo[0], leafLo[1]), rootHi = max(leafHi[0], leafHi[1]);
  currentCost = boxArea(rootLo, rootHi);
  uint leaves = 2u;
  while (leaves < kTreeletLeaves) {
    // Open the largest internal subtree: that is where a better split pays most.
    uint best = kBvhNone;
    float bestBoxArea = -1.0;
    for (uint j = 0u; j < leaves; ++j) {
      float a = boxArea(leafLo[j], leafHi[j]);
      if ((leafRef[j] & kBvhLeafBit) == 0u && a > bestBoxArea) {
        best = j;
        bestBoxArea = a;
      }
    }
    if (best == kBvhNone) break;
    uint opened = leafRef[best];
    internalNode[internals++] = opened;
    currentCost += bestBoxArea;
    leafRef[best] = nodes[opened].child[0];
    childBox(entry, nodes[opened].child[0u], leafLo[best], leafHi[best]);
    leafRef[leaves] = nodes[opened].child[1];
    childBox(entry, nodes[opened].child[1u], leafLo[leaves], leafHi[leaves]);
    ++leaves;
  }
  for (uint j = 0u; j < leaves; ++j) currentCost += refCost(leafRef[j], leafLo[j], leafHi[j]);
  return leaves;
}

// Cheapest binary tree over every subset of the treelet's leaves; smaller
// subsets come first in numeric order, so each split's halves are known.
void optimise(uint leaves) {
  uint full = (1u << leaves) - 1u;
  for (uint s = 1u; s <= full; ++s) {
    // A subset's box: the box of the subset without its lowest leaf, plus that leaf.
    uint j = uint(findLSB(s)), rest = s & (s - 1u);
    subsetLo[s] = rest == 0u ? leafLo[j] : min(subsetLo[rest], leafLo[j]);
    subsetHi[s] = rest == 0u ? leafHi[j] : max(subsetHi[rest], leafHi[j]);
    if (rest == 0u) {
      subsetCost[s] = refCost(leafRef[j], leafLo[j], leafHi[j]);
      subsetSplit[s] = 0u;
      continue;
    }
    // Each split once: the side holding the lowest leaf is enumerated.
    uint lowest = s & (~s + 1u);
    float best = 1.0 / 0.0;
    uint bestPart = lowest;
    for (uint part = (s - 1u) & s; part != 0u; part = (part - 1u) & s) {
      if ((part & lowest) == 0u) continue;
      float c = subsetCost[part] + subsetCost[s ^ part];
      if (c < best) {
        best = c;
        bestPart = part;
      }
    }
    subsetCost[s] = boxArea(subsetLo[s], subsetHi[s]) + best;
    subsetSplit[s] = bestPart;
  }
}

void setParent(uint ref, uint parent) {
  if ((ref & kBvhLeafBit) == 0u) nodes[ref].parent = parent;
}

// Rewires the treelet's internal nodes into the tree optimise() chose.
void rewire(uint leaves) {
  uint pendingSubset[kTreeletInternal], pendingNode[kTreeletInternal];
  uint pending = 1u, used = 1u;
  pendingSubset[0] = (1u << leaves) - 1u;
  pendingNode[0] = internalNode[0];
  while (pending > 0u) {
    --pending;
    uint s = pendingSubset[pending], node = pendingNode[pending];
    uint sides[2] = uint[2](subsetSplit[s], s ^ subsetSplit[s]);
    uint total = 0u;
    for (uint c = 0u; c < 2u; ++c) {
      uint side = sides[c];
      uint ref;
      if (bitCount(side) == 1) {
        ref = leafRef[findLSB(side)];
      } else {
        ref = internalNode[used++];
        pendingSubset[pending] = side;
        pendingNode[pending] = ref;
        ++pending;
      }
      nodes[node].child[c] = ref;
      setParent(ref, node | (c == 1u ? kBvhParentRight : 0u));
    }
    // A union of the subtrees' exact boxes: exact again.
    for (uint a = 0u; a < 3u; ++a) {
      exact[6u * node + a] = subsetLo[s][a];
      exact[6u * node + 3u + a] = subsetHi[s][a];
    }
    uint below = 0u;
    for (uint j = 0u; j < leaves; ++j) {
      if ((s & (1u << j)) != 0u) below += refLeaves(leafRef[j]);
    }
    nodeStats[node] = uvec2(floatBitsToUint(subsetCost[s]), below);
  }
}

// Settles one node whose subtrees are final: restructures it when it is large
// enough for a full treelet, and records its cost and leaf count for the nodes above.
void settle(uint node) {
  uint leavesBelow = refLeaves(nodes[node].child[0]) + refLeaves(nodes[node].child[1]);
  float currentCost;
  uint leaves = leavesBelow >= kTreeletLeaves ? formTreelet(node, currentCost) : 0u;
  if (leaves >= 3u) {
    optimise(leaves);
    if (subsetCost[(1u << leaves) - 1u] < currentCost * (1.0 - kMinGain)) {
      rewire(leaves);
      return;
    }
  } else {
    vec3 lo0, hi0, lo1, hi1;
    childBox(entry, nodes[node].child[0u], lo0, hi0);
    childBox(entry, nodes[node].child[1u], lo1, hi1);
    currentCost = boxArea(min(lo0, lo1), max(hi0, hi1)) + refCost(nodes[node].child[0], lo0, hi0) +
                  refCost(nodes[node].child[1], lo1, hi1);
  }
  nodeStats[node] = uvec2(floatBitsToUint(currentCost), leavesBelow);
}

#include "bvh_entry_of.glsl"

// Whether `node`'s subtrees are both settled after this arrival. Release
// what this invocation settled below, acquire what the sibling's did.
bool arrive(uint node) {
  return atomicAdd(counters[node], 1u, gl_ScopeDevice, gl_StorageSemanticsBuffer, gl_SemanticsAcquireRelease) == 1u;
}

// One invocation per node slot of the build; the walk starts at the nodes
// that hold a leaf, as the refit's does.
void main() {
  uint t = invocationIndex();
  if (t >= pc.count) return;
  entry = entries[jobOf(t)];
  uint local = t - entry.base;
  if (local + 1u >= entry.count) return;  // a group of n leaves has n - 1 nodes
  uint node = entry.first + local;
  bool leaf0 = (nodes[node].child[0] & kBvhLeafBit) != 0u, leaf1 = (nodes[node].child[1] & kBvhLeafBit) != 0u;
  if (!leaf0 && !leaf1) return;
  bool settled = (leaf0 && leaf1) || arrive(node);
  for (uint step = 0u; settled && step < kBvhMaxDepth; ++step) {
    settle(node);
    uint parent = nodes[node].parent;
    if (parent == kBvhNone) break;
    node = parent & ~kBvhParentRight;
    if (node >= pc.total) break;
    settled = arrive(node);
  }
}
