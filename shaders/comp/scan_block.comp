// Prefix sum, steps 2 and 3: exclusive scan of each workgroup's tile in place,
// plus the already-scanned sum of the tiles before it when addPartials is set.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../shared/prefix_sum.h"

layout(local_size_x_id = kScanSpecWorkgroupSize) in;
layout(constant_id = kScanSpecItemsPerThread) const uint ITEMS_PER_THREAD = 8;
layout(constant_id = kScanSpecMaxSubgroups) const uint MAX_SUBGROUPS = 32;
#include "../common/workgroup.glsl"

layout(push_constant) uniform Push { ScanPush pc; };
layout(std430, binding = kScanBindingData) buffer Data { uint data[]; };
layout(std430, binding = kScanBindingPartials) readonly buffer Partials { uint partials[]; };

const uint kTile = gl_WorkGroupSize.x * ITEMS_PER_THREAD;
// One padding word every 32 keeps the blocked reads below free of bank conflicts.
shared uint sTile[kTile + kTile / 32];
uint padded(uint i) { return i + (i >> 5); }

void main() {
  uint block = workgroupIndex();
  if (block >= pc.blockCount) return;  // uniform per workgroup
  uint base = block * kTile;
  uint r = scanOrderIndex();
  // Coalesced (striped) loads, then each invocation scans a run of consecutive items.
  for (uint i = 0; i < ITEMS_PER_THREAD; ++i) {
    uint local = i * gl_WorkGroupSize.x + r;
    uint index = base + local;
    sTile[padded(local)] = index < pc.count ? data[index] : 0u;
  }
  barrier();
  uint runSum = 0;
  for (uint i = 0; i < ITEMS_PER_THREAD; ++i) runSum += sTile[padded(r * ITEMS_PER_THREAD + i)];
  uint total;
  uint running = workgroupExclusiveAdd(runSum, total);
  if (pc.addPartials != 0u) running += partials[block];
  for (uint i = 0; i < ITEMS_PER_THREAD; ++i) {
    uint slot = padded(r * ITEMS_PER_THREAD + i);
    uint value = sTile[slot];
    sTile[slot] = running;
    running += value;
  }
  barrier();
  for (uint i = 0; i < ITEMS_PER_THREAD; ++i) {
    uint local = i * gl_WorkGroupSize.x + r;
    uint index = base + local;
    if (index < pc.count) data[index] = sTile[padded(local)];
  }
}
