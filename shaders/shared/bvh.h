// Layout shared by the BVH shaders (shaders/comp/bvh_*.comp), the trace pass
// and src/render/bvh.cpp. One build makes a forest: each group of primitives
// (a shape's triangles, or all instances for the top level) gets its own
// binary tree, one primitive per leaf, built LBVH-style (Karras 2012).
#ifndef SNELL_BVH_H
#define SNELL_BVH_H
#include "shared_types.h"

SNELL_GPU_BEGIN

// A child reference with this bit set is a leaf; the rest is the primitive id
// (a global triangle index, or an instance index in the top level).
SNELL_CONST kBvhLeafBit = 0x80000000u;
SNELL_CONST kBvhNone = 0xffffffffu;  // no parent (a group's root), or no root (an empty group)
// Morton codes use 10 bits per axis; a primitive's group sits above them in
// the 64-bit sort key, so one sort orders every group and the Karras
// hierarchy separates groups before it splits any of them.
SNELL_CONST kBvhMortonBits = 30;
// Longest leaf-to-root walk a refit will take; a corrupted parent chain ends there.
SNELL_CONST kBvhMaxDepth = 256;

// Binding slots of set 0 (each pass binds the ones it declares).
SNELL_CONST kBvhBindingPrimBoxes = 0;   // float[6 * count]: lo xyz, hi xyz per primitive
SNELL_CONST kBvhBindingPrimGroups = 1;  // uint[count]: the group of each primitive
SNELL_CONST kBvhBindingGroups = 2;      // BvhGroup[groupCount]
SNELL_CONST kBvhBindingKeys = 3;        // uvec2[count]: 64-bit sort keys (lo, hi)
SNELL_CONST kBvhBindingLeafPrims = 4;   // uint[count]: primitive at each sorted leaf position
SNELL_CONST kBvhBindingNodes = 5;       // BvhNode[count - 1]: internal nodes
SNELL_CONST kBvhBindingLeafParents = 6; // uint[count]: parent node of each primitive's leaf
SNELL_CONST kBvhBindingCounters = 7;    // uint[count - 1]: arrivals per node, zeroed before each fit
// Primitive boxes from triangles (bvh_triangle_boxes.comp) or instances (bvh_instance_boxes.comp).
SNELL_CONST kBvhBindingPositions = 8;   // float[3 * vertexCount]
SNELL_CONST kBvhBindingIndices = 9;     // uint[3 * triangleCount], absolute vertex indices
SNELL_CONST kBvhBindingInstances = 10;  // GpuInstance[instanceCount]
SNELL_CONST kBvhBindingBlasGroups = 11; // BvhGroup[geometryCount] of the bottom level
// Treelet restructuring (bvh_restructure.comp): uvec2[count - 1], each internal
// node's subtree cost (float bits) and leaf count. The build binds the keys
// buffer here: the keys are spent once the hierarchy exists.
SNELL_CONST kBvhBindingNodeStats = 12;
SNELL_CONST kBvhBindingDropped = 13;    // uint: triangles boxed empty because a vertex was not finite

SNELL_CONST kBvhSpecWorkgroupSize = 0;

// 64 bytes, total: 64 bytes
struct BvhNode {
  float box[12];   // 48: child 0 lo xyz, hi xyz; child 1 lo xyz, hi xyz
  uint child[2];   // 8: internal node index, or kBvhLeafBit | primitive
  uint parent;     // 4: kBvhNone at a group's root
  uint pad0;       // 4
};

// 64 bytes, total: 64 bytes
struct BvhGroup {
  uint centroidLo[3];  // 12: order-preserving float keys, atomicMin
  uint centroidHi[3];  // 12: the same keys inverted, atomicMin (so both reset to ~0)
  uint root;           // 4: internal node index, kBvhLeafBit | primitive, or kBvhNone
  uint first;          // 4: first primitive (and first sorted leaf) of the group
  float boxLo[3];      // 12: the root's box, written by every fit
  float boxHi[3];      // 12
  uint count;          // 4: primitives in the group
  uint pad0;           // 4
};

// 16 bytes, total: 16 bytes
struct BvhPush {
  uint count;       // 4: primitives (or leaves) this dispatch covers
  uint first;       // 4: the first of them
  uint groupCount;  // 4
  uint total;       // 4: primitives in the whole forest
};

// One placed shape: a bottom-level tree and its transform, camera-relative.
// 112 bytes, total: 112 bytes
struct GpuInstance {
  vec4 objectToWorld[3];  // 48: rows of a 3x4 matrix
  vec4 worldToObject[3];  // 48: rows of its inverse
  uint geometry;          // 4: the bottom-level group
  uint material;          // 4: index into the material table
  uint pad0;              // 4
  uint pad1;              // 4
};

SNELL_GPU_END
#endif
