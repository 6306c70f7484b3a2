// Radix sort, step 1 of each pass: each workgroup counts the digits of its tile
// and writes the counts digit-major, so that one exclusive scan of the whole
// histogram gives every (digit, block) its first output position.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "../shared/radix_sort.h"

layout(local_size_x_id = kSortSpecWorkgroupSize) in;
layout(constant_id = kSortSpecKeysPerThread) const uint KEYS_PER_THREAD = 8;
layout(constant_id = kSortSpecMaxSubgroups) const uint MAX_SUBGROUPS = 32;
layout(constant_id = kSortSpecKeyWords) const uint KEY_WORDS = 1;
#include "../common/workgroup.glsl"

layout(push_constant) uniform Push { SortPush pc; };
layout(std430, binding = kSortBindingKeysIn) readonly buffer KeysIn { uint keysIn[]; };
layout(std430, binding = kSortBindingHistogram) writeonly buffer Histogram { uint histogram[]; };

shared uint sCount[kSortRadix];

void main() {
  uint block = workgroupIndex();
  if (block >= pc.blockCount) return;  // uniform per workgroup
  uint r = scanOrderIndex();
  for (uint d = r; d < kSortRadix; d += gl_WorkGroupSize.x) sCount[d] = 0;
  barrier();
  uint tile = gl_WorkGroupSize.x * KEYS_PER_THREAD;
  uint word = KEY_WORDS == 1u ? 0u : (pc.shift >> 5);
  uint bit = pc.shift & 31u;
  [[unroll]] for (uint i = 0; i < KEYS_PER_THREAD; ++i) {
    uint index = block * tile + i * gl_WorkGroupSize.x + r;
    // Past the end every key reads as all ones: padding sorts last in every pass,
    // which lands it beyond `count` where the scatter drops it.
    uint keyWord = index < pc.count ? keysIn[index * KEY_WORDS + word] : 0xFFFFFFFFu;
    atomicAdd(sCount[(keyWord >> bit) & (kSortRadix - 1)], 1u);
  }
  barrier();
  for (uint d = r; d < kSortRadix; d += gl_WorkGroupSize.x) {
    histogram[d * pc.blockCount + block] = sCount[d];
  }
}
