// Prefix sum, step 1 of 3: each workgroup writes the sum of its tile.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../shared/prefix_sum.h"

layout(local_size_x_id = kScanSpecWorkgroupSize) in;
layout(constant_id = kScanSpecItemsPerThread) const uint ITEMS_PER_THREAD = 8;
layout(constant_id = kScanSpecMaxSubgroups) const uint MAX_SUBGROUPS = 32;
#include "../common/workgroup.glsl"

layout(push_constant) uniform Push { ScanPush pc; };
layout(std430, binding = kScanBindingData) readonly buffer Data { uint data[]; };
layout(std430, binding = kScanBindingPartials) writeonly buffer Partials { uint partials[]; };

void main() {
  uint block = workgroupIndex();
  if (block >= pc.blockCount) return;  // uniform per workgroup, so no barrier is skipped by part of it
  uint tile = gl_WorkGroupSize.x * ITEMS_PER_THREAD;
  uint base = block * tile;
  uint r = scanOrderIndex();
  uint sum = 0;
  for (uint i = 0; i < ITEMS_PER_THREAD; ++i) {
    uint index = base + i * gl_WorkGroupSize.x + r;
    sum += index < pc.count ? data[index] : 0u;
  }
  uint total;
  workgroupExclusiveAdd(sum, total);
  if (r == 0) partials[block] = total;
}
