// Layout shared by the BVH shaders (shaders/comp/bvh/*.comp), the trace pass
// and src/render/bvh.cpp.
//
// A forest is one set of buffers holding many binary trees, one per group of
// primitives: each shape's triangles in the bottom level, all instances in
// the top level. A leaf holds one primitive.
//
// Builds run H-PLOC (Benthin et al. 2024): Apetrei's bottom-up LBVH over the
// Morton-sorted primitives, with PLOC clustering inside each range once it
// holds more than half a window of clusters. A merge of clusters A and B gets
// the node slot max(first sorted position in A, first in B) - 1: every binary
// tree over a group's n leaves numbers its n - 1 nodes this way without
// collision, so slots are deterministic, whatever order the GPU runs the
// merges in, and a group owns exactly [first, first + count - 1). H-PLOC
// writes each node's links and its exact box (in the forest's exact boxes,
// which refits use the same way); one pass then stores every node's
// children's boxes as the trace reads them (exact, or quantised in it).
#ifndef SNELL_BVH_H
#define SNELL_BVH_H
#include "shared_types.h"

SNELL_GPU_BEGIN

// Child references: a node slot, or kBvhLeafBit | the primitive (a global
// triangle index in the bottom level, an instance in the top level).
SNELL_CONST kBvhLeafBit = 0x80000000u;
SNELL_CONST kBvhNone = 0xffffffffu;  // no parent (a group's root), no root (an empty group), no cluster
SNELL_CONST kBvhParentRight = 0x80000000u;  // in BvhNode::parent: the node is its parent's child 1
// In BvhNode::scale: flips at each arrival of a refit; clear between refits.
SNELL_CONST kBvhArrivalBit = 0x01000000u;
SNELL_CONST kBvhMaxPrimitives = 0x7fffffffu;
// Morton codes use 10 bits per axis; the build entry of a primitive sits above
// them in the sort key, so one sort orders every group of a build.
SNELL_CONST kBvhMortonBits = 30;
// Longest leaf-to-root walk a refit will take, and the most levels a build
// climbs; a corrupted tree ends there instead of looping.
SNELL_CONST kBvhMaxDepth = 256;
// H-PLOC: clusters one workgroup merges at a time, half of them kept per range
// (the paper's 32, and its search radius of 8).
SNELL_CONST kBvhWindow = 32;
SNELL_CONST kBvhSearchRadius = 8;
// SAH statistics are fixed point: kBvhSahScale units per the root area of the
// group's last build, so sums are exact and independent of atomic order.
SNELL_CONST kBvhSahScale = 65536;
SNELL_CONST kBvhSahTermCap = 1048576;  // one node counts at most 16 build roots

// Binding slots of set 0 (each pass binds the ones it declares).
SNELL_CONST kBvhBindingPrimBoxes = 0;     // float[6 * count]: lo xyz, hi xyz per primitive of a build, packed
SNELL_CONST kBvhBindingBuildEntries = 1;  // BvhBuildEntry[entryCount]
SNELL_CONST kBvhBindingRefitEntries = 2;  // BvhRefitEntry[entryCount]
SNELL_CONST kBvhBindingKeys = 3;          // uint[count] or uvec2[count]: sort keys (lo, hi)
SNELL_CONST kBvhBindingValues = 4;        // uint[count]: primitive ids, sorted with the keys
SNELL_CONST kBvhBindingParentIds = 5;     // uint[count]: H-PLOC's meeting points, kBvhNone before a build
SNELL_CONST kBvhBindingClusters = 6;      // BvhCluster[count]: each clustered range's clusters, from its first position
SNELL_CONST kBvhBindingNodes = 7;         // BvhNode[]
SNELL_CONST kBvhBindingGroups = 10;       // BvhGroup[groupCount]
SNELL_CONST kBvhBindingStats = 11;        // uvec4[groupCount]: last refit's fixed-point SAH sum (lo, hi), root area, build's root area
SNELL_CONST kBvhBindingDropped = 12;      // uint: triangles boxed empty because a vertex was not finite
SNELL_CONST kBvhBindingPositions = 13;    // float[3 * vertexCount]
SNELL_CONST kBvhBindingIndices = 14;      // uint[3 * triangleCount], absolute vertex indices
SNELL_CONST kBvhBindingInstances = 15;    // GpuInstance[instanceCount]
SNELL_CONST kBvhBindingBlasGroups = 16;   // BvhGroup[] of the bottom level
SNELL_CONST kBvhBindingCounters = 17;     // uint[nodes]: arrivals of the restructuring pass
SNELL_CONST kBvhBindingNodeStats = 18;    // uvec2[nodes]: subtree cost and leaf count (restructuring)
SNELL_CONST kBvhBindingExactBoxes = 19;   // float[6 * nodes]: each node's exact box during a build or a refit
SNELL_CONST kBvhBindingChildBoxes = 20;   // vec4[3 * nodes]: each node's children's exact boxes (kBvhFlagChildBoxes)
SNELL_CONST kBvhBindingWideRecords = 21;  // BvhWideEntry[4 * nodes]: each node's 4-wide record (kBvhFlagWideRecords)

SNELL_CONST kBvhSpecWorkgroupSize = 0;
SNELL_CONST kBvhSpecSlots = 1;  // H-PLOC: window slots per invocation, window / smallest subgroup
SNELL_CONST kBvhSpecTeams = 2;  // H-PLOC: subgroups per workgroup at the smallest subgroup size

SNELL_CONST kBvhFlagInstances = 1u;  // leaves are instances (top level), else triangles
SNELL_CONST kBvhFlagKeys32 = 2u;     // sort keys are 32-bit
SNELL_CONST kBvhFlagChildBoxes = 4u; // the forest keeps each node's children's exact boxes for the trace
SNELL_CONST kBvhFlagWideRecords = 8u; // and each node's 4-wide record (BvhWideEntry)

// A node holds its two children's boxes quantised to 8 bits per coordinate
// within its own box (Ylitie, Karras and Laine 2017 do the same for wide
// nodes): the box's low corner in float, a power-of-two step per axis, and
// for each child the number of steps to its box's faces, rounded outwards,
// so a decoded box always holds what it bounds. A child whose low step on x
// exceeds its high one is empty.
//
// Unless a forest is compact, builds and refits also keep each node's two
// children's exact boxes beside it (kBvhBindingChildBoxes, 48 bytes: lo0 hi0
// lo1 hi1 in three vec4s, an empty child as the point at +infinity), and the
// trace reads those: a child test is then a slab and no decode, which is
// most of what a walk spends (bench/results/walk-counts.md). Such a forest's
// nodes hold only links (child, parent, the refit's arrival bit): no pass
// writes or reads their quantised fields.
SNELL_CONST kBvhChildBoxBytes = 48;  // a node's exact child boxes, as above
// 40 bytes, total: 40 bytes
struct BvhNode {
  float origin[3];  // 12: the node box's low corner
  uint scale;       // 4: bits 0-23: the biased exponent of each axis's step (x, y, z); bit 24: refit arrivals (kBvhArrivalBit)
  uint quant[3];    // 12: bytes 0-5: child 0's lo xyz, hi xyz in steps; bytes 6-11: child 1's
  uint child[2];    // 8: node index, or a leaf reference
  uint parent;      // 4: kBvhNone at a group's root; else the parent's slot, kBvhParentRight set when this is its child 1
};

// A bottom-level forest with exact child boxes also keeps, for each node, a
// record of four entries the trace walks 4 wide (kBvhBindingWideRecords),
// where the records fit one buffer the device binds (render/bvh.h:
// keepsWideRecords):
// entries 2 c and 2 c + 1 are child c's two children, or child c itself and
// an empty entry where child c is a leaf. A visit reads one record and tests
// four boxes, and enters a grandchild, so a walk visits every other level:
// 39-45% fewer dependent node reads than the binary walk for the same
// triangles (bench/results/walk-counts.md, step 2e). Each node writes its
// share as a build or refit completes it: its children into its parent's
// record, a leaf child into its own, so records need no depth and no pass of
// their own. An empty entry is the point at +infinity (no slab enters it)
// with kBvhNone. The trace reads an entry as two vec4s: lo and the ref's
// bits, hi and the parent's.
// 32 bytes, total: 32 bytes
struct BvhWideEntry {
  float lo[3];  // 12
  uint ref;     // 4: node slot or leaf reference; kBvhNone where empty
  float hi[3];  // 12
  uint parent;  // 4: child c of the record's node for entries 2 c and 2 c + 1; kBvhNone where child c stands for itself
};

// 64 bytes, total: 64 bytes
struct BvhGroup {
  float boxLo[3];    // 12: the root's box, written by every build and refit
  float boxHi[3];    // 12
  uint root;         // 4: node slot, leaf reference, or kBvhNone
  uint first;        // 4: first primitive, and first node slot
  uint count;        // 4: primitives (count - 1 node slots)
  float buildArea;   // 4: surface area of the root box at the group's last build
  uint pad0;         // 4
  uint pad1;         // 4
  uint pad2;         // 4
  uint pad3;         // 4
  uint pad4;         // 4
  uint pad5;         // 4
};

// One group of a build, its primitives packed after those of earlier entries.
// 48 bytes, total: 48 bytes
struct BvhBuildEntry {
  uint group;          // 4
  uint first;          // 4: the group's first primitive
  uint count;          // 4
  uint base;           // 4: its first primitive in the build's packed arrays
  uint centroidLo[3];  // 12: order-preserving float keys, atomicMin (~0 before the build)
  uint centroidHi[3];  // 12: the same keys inverted, atomicMin
  uint pad0;           // 4
  uint pad1;           // 4
};

// One group of a refit: its node slots (or its one leaf) take threads [threadBase, + max(count - 1, 1)).
// 16 bytes, total: 16 bytes
struct BvhRefitEntry {
  uint group;       // 4
  uint first;       // 4
  uint count;       // 4
  uint threadBase;  // 4
};

// A cluster H-PLOC hands from one level to the next: a subtree and its box.
// 32 bytes, total: 32 bytes
struct BvhCluster {
  uint ref;      // 4: node slot or leaf reference; kBvhNone ends a range's list
  uint first;    // 4: its first sorted position (which names the slot of the node it merges into)
  float lo[3];   // 12
  float hi[3];   // 12
};

// 16 bytes, total: 16 bytes
struct BvhPush {
  uint count;       // 4: threads of this dispatch
  uint entryCount;  // 4
  uint flags;       // 4: kBvhFlag*
  uint total;       // 4: node slots of the forest (bounds checks)
};

// One placed shape: a bottom-level tree and its transform, relative to the
// frame's origin.
// 112 bytes, total: 112 bytes
struct GpuInstance {
  vec4 objectToWorld[3];  // 48: rows of a 3x4 matrix
  vec4 worldToObject[3];  // 48: rows of its inverse
  uint geometry;          // 4: the bottom-level group
  uint material;          // 4: index into the material table
  uint flags;             // 4: kInstance*
  uint pad1;              // 4
};

// GpuInstance::flags
// Its faces are seen from their front only (a single-sided material, glTF's
// and USD's doubleSided false, that is not glass): rays pass their backs.
SNELL_CONST kInstanceCullBackFaces = 1u;

SNELL_GPU_END
#endif
