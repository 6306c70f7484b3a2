// The masked trace's first step: the raster pass's depth pre-pass left a mask
// (non-zero where the visible face is transmissive); this pass lists those
// pixels, tile by tile, so the trace runs one invocation per pixel that
// refracts and none elsewhere. The last workgroup to finish writes the
// trace's indirect dispatch: no workgroup waits for another.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_memory_scope_semantics : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "../shared/trace.h"

layout(local_size_x = 64) in;  // one kTraceTile x kTraceTile tile
layout(push_constant) uniform Push { TraceCompactPush pc; };
layout(binding = kTraceBindingMask, r32ui) uniform readonly uimage2D mask;
layout(std430, binding = kTraceBindingPixels) coherent buffer Pixels {
  TracePixelListHeader list;
  uint listed[];
};

void main() {
  uint tile = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  uvec2 pixel = uvec2(tile % pc.tilesX, tile / pc.tilesX) * kTraceTile +
                uvec2(gl_LocalInvocationID.x % kTraceTile, gl_LocalInvocationID.x / kTraceTile);
  bool take = pixel.x < pc.width && pixel.y < pc.height && imageLoad(mask, ivec2(pixel)).r != 0u;
  // One atomic per subgroup for its pixels.
  uvec4 ballot = subgroupBallot(take);
  uint base = 0u;
  if (subgroupElect()) base = atomicAdd(list.count, subgroupBallotBitCount(ballot));
  base = subgroupBroadcastFirst(base);
  if (take) listed[base + subgroupBallotExclusiveBitCount(ballot)] = pixel.x | (pixel.y << 16);

  // Every count of this workgroup happens before its finish is counted.
  controlBarrier(gl_ScopeWorkgroup, gl_ScopeDevice, gl_StorageSemanticsBuffer, gl_SemanticsAcquireRelease);
  if (gl_LocalInvocationID.x != 0u) return;
  uint groups = gl_NumWorkGroups.x * gl_NumWorkGroups.y;
  uint done = atomicAdd(list.groupsDone, 1u, gl_ScopeDevice, gl_StorageSemanticsBuffer, gl_SemanticsAcquireRelease);
  if (done + 1u != groups) return;
  uint count = atomicAdd(list.count, 0u, gl_ScopeDevice, gl_StorageSemanticsBuffer, gl_SemanticsAcquireRelease);
  uint traceGroups = (count + 63u) / 64u;
  uint x = min(traceGroups, pc.maxGroupsX);
  list.dispatchX = x;
  list.dispatchY = x == 0u ? 0u : (traceGroups + x - 1u) / x;
  list.dispatchZ = 1u;
}
