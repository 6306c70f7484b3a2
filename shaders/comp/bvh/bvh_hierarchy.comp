// Build step 4, after the sort: the binary radix tree over the sorted keys
// (Karras 2012), every internal node found independently in one dispatch.
// Keys carry the group above the Morton code, so the tree splits groups
// apart before it splits any group; the node that spans exactly one group is
// that group's root, and the links above it are cut.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "bvh_common.glsl"

layout(std430, binding = kBvhBindingKeys) readonly buffer Keys { uvec2 keys[]; };
layout(std430, binding = kBvhBindingLeafPrims) readonly buffer LeafPrims { uint leafPrims[]; };
layout(std430, binding = kBvhBindingNodes) writeonly buffer Nodes { BvhNode nodes[]; };
layout(std430, binding = kBvhBindingLeafParents) writeonly buffer LeafParents { uint leafParents[]; };
layout(std430, binding = kBvhBindingGroups) buffer Groups { BvhGroup groups[]; };

int n;  // leaves

// Length of the common prefix of the keys at sorted positions i and j; equal
// keys fall back to their positions, so every key is distinct. -1 outside.
int delta(int i, int j) {
  if (j < 0 || j >= n) return -1;
  uvec2 a = keys[i], b = keys[j];
  if (a.y != b.y) return 31 - findMSB(a.y ^ b.y);
  if (a.x != b.x) return 63 - findMSB(a.x ^ b.x);
  return 95 - findMSB(uint(i ^ j));
}

uint groupAt(int i) {
  uvec2 k = keys[i];
  return (k.y << (32u - kBvhMortonBits)) | (k.x >> kBvhMortonBits);
}

// Whether sorted positions [first, last] hold one whole group.
bool wholeGroup(int first, int last) {
  uint g = groupAt(first);
  return groupAt(last) == g && (first == 0 || groupAt(first - 1) != g) && (last == n - 1 || groupAt(last + 1) != g);
}

void link(uint parent, int first, int last, bool isLeaf, int index) {
  uint ref = isLeaf ? (kBvhLeafBit | leafPrims[index]) : uint(index);
  uint up = parent;
  if (wholeGroup(first, last)) {
    groups[groupAt(first)].root = ref;
    up = kBvhNone;
  }
  if (isLeaf) leafParents[leafPrims[index]] = up;
  else nodes[index].parent = up;
}

void main() {
  n = int(pc.total);
  int i = int(threadIndex());
  if (n == 1 && i == 0) {
    link(kBvhNone, 0, 0, true, 0);
    return;
  }
  if (i >= n - 1) return;

  // Direction of the node's range, and its other end by exponential then binary search.
  int d = delta(i, i + 1) > delta(i, i - 1) ? 1 : -1;
  int minPrefix = delta(i, i - d);
  int span = 2;
  while (delta(i, i + span * d) > minPrefix) span *= 2;  // ends: delta is -1 past either end
  int l = 0;
  for (int t = span / 2; t >= 1; t /= 2) {
    if (delta(i, i + (l + t) * d) > minPrefix) l += t;
  }
  int j = i + l * d;
  int nodePrefix = delta(i, j);
  // The split: the last position sharing more than nodePrefix bits with i.
  int s = 0;
  int t = l;
  do {
    t = (t + 1) / 2;
    if (delta(i, i + (s + t) * d) > nodePrefix) s += t;
  } while (t > 1);
  int split = i + s * d + min(d, 0);

  int first = min(i, j), last = max(i, j);
  bool leftLeaf = first == split, rightLeaf = last == split + 1;
  nodes[i].child[0] = leftLeaf ? (kBvhLeafBit | leafPrims[split]) : uint(split);
  nodes[i].child[1] = rightLeaf ? (kBvhLeafBit | leafPrims[split + 1]) : uint(split + 1);
  link(uint(i), first, split, leftLeaf, split);
  link(uint(i), split + 1, last, rightLeaf, split + 1);
  // Node 0 is nobody's child; it is a root when one group fills the forest.
  if (i == 0) {
    if (wholeGroup(0, n - 1)) groups[groupAt(0)].root = 0u;
    nodes[0].parent = kBvhNone;
  }
}
