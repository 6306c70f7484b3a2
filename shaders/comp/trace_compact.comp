// The masked trace's first step: the raster pass's depth pre-pass left a mask
// (non-zero where the visible face is transmissive); this pass lists those
// pixels, tile by tile, so the trace runs one invocation per pixel that
// refracts and none elsewhere. Each subgroup that lists pixels raises the
// trace's indirect workgroup rows to cover them: no workgroup waits for another.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "../shared/trace.h"

layout(local_size_x = 64) in;  // one kTraceTile x kTraceTile tile
#include "../common/dispatch.glsl"
layout(push_constant) uniform Push { TraceCompactPush pc; };
layout(binding = kTraceBindingMask, r32ui) uniform readonly uimage2D mask;
layout(std430, binding = kTraceBindingPixels) coherent buffer Pixels {
  TracePixelListHeader list;
  uint listed[];
};

void main() {
  uint group = workgroupIndex();
  uint tiles = pc.tilesX * ((pc.height + kTraceTile - 1u) / kTraceTile);
  for (uint k = 0u; k < kTraceCompactTiles; ++k) {
    uint tile = group * kTraceCompactTiles + k;
    if (tile >= tiles) break;  // uniform: the whole workgroup leaves together
    uvec2 pixel = uvec2(tile % pc.tilesX, tile / pc.tilesX) * kTraceTile +
                  uvec2(gl_LocalInvocationID.x % kTraceTile, gl_LocalInvocationID.x / kTraceTile);
    bool take = pixel.x < pc.width && pixel.y < pc.height && imageLoad(mask, ivec2(pixel)).r != 0u;
    // One atomic per subgroup that has pixels, and one for the trace's workgroup count.
    uvec4 ballot = subgroupBallot(take);
    uint n = subgroupBallotBitCount(ballot);
    if (n == 0u) continue;
    uint base = 0u;
    if (subgroupElect()) {
      base = atomicAdd(list.count, n);
      // The trace's workgroups, 64 invocations each, lanesPerPixel of them a pixel.
      uint groups = ((base + n) * pc.lanesPerPixel + gl_WorkGroupSize.x - 1u) / gl_WorkGroupSize.x;
      atomicMax(list.dispatchY, (groups + kTraceListGroupsX - 1u) / kTraceListGroupsX);
    }
    base = subgroupBroadcastFirst(base);
    if (take) listed[base + subgroupBallotExclusiveBitCount(ballot)] = pixel.x | (pixel.y << 16);
  }
}
