// The refine pass: a subdivision cage, moved by its host, becomes the
// shape's vertices (shared/refine.h has the two stages and the tables).
// The CPU twin, src/ref/refine.cpp, walks the same tables in double.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../shared/refine.h"

layout(local_size_x_id = kRefineSpecWorkgroupSize) in;
layout(constant_id = kRefineSpecStage) const uint kStage = kRefineStageRefine;

layout(push_constant) uniform Push { RefinePush pc; };
layout(std430, binding = kRefineBindingCage) readonly buffer Cage { float cage[]; };
layout(std430, binding = kRefineBindingWords) readonly buffer Words { uint words[]; };
layout(std430, binding = kRefineBindingWeights) readonly buffer Weights { float weights[]; };
layout(std430, binding = kRefineBindingRefined) buffer Refined { float refined[]; };
layout(std430, binding = kRefineBindingPositions) writeonly buffer Positions { float positions[]; };
layout(std430, binding = kRefineBindingNormals) writeonly buffer Normals { float normals[]; };
layout(std430, binding = kRefineBindingJobs) readonly buffer Jobs { RefineJob jobs[]; };

// Each stage numbers its own invocations: a job's first is its refineBase in
// the refine stage and its limitBase in the limit stage.
#define JOB_FIRST(i) (kStage == kRefineStageRefine ? jobs[i].refineBase : jobs[i].limitBase)
#define JOB_COUNT pc.jobCount
#include "../common/dispatch.glsl"

vec3 cageAt(uint v) { return vec3(cage[3u * v], cage[3u * v + 1u], cage[3u * v + 2u]); }
vec3 refinedAt(uint v) { return vec3(refined[3u * v], refined[3u * v + 1u], refined[3u * v + 2u]); }

// Row r of the table whose offsets start at `offsets`, as [first, end), no longer than the guard.
uvec2 rowOf(uint offsets, uint r) {
  uint first = words[offsets + r];
  return uvec2(first, min(words[offsets + r + 1u], first + kRefineMaxRow));
}

void refineVertex(RefineJob job, uint r) {
  uvec2 row = rowOf(job.refineOffsets, r);
  vec3 p = vec3(0.0);
  for (uint k = row.x; k < row.y; ++k) {
    p += weights[job.refineWeights + k] * cageAt(job.cageFirst + words[job.refineIndices + k]);
  }
  uint o = 3u * (job.refinedFirst + r);
  refined[o] = p.x;
  refined[o + 1u] = p.y;
  refined[o + 2u] = p.z;
}

void limitVertex(RefineJob job, uint v) {
  uint r = words[job.vertexOf + v];
  vec3 p = refinedAt(job.refinedFirst + r);
  vec3 n = vec3(0.0);
  if ((job.flags & (kRefineFlagLimitSurface | kRefineFlagLimitNormals)) != 0u) {
    uvec2 row = rowOf(job.limitOffsets, r);
    vec3 limit = vec3(0.0), t1 = vec3(0.0), t2 = vec3(0.0);
    for (uint k = row.x; k < row.y; ++k) {
      vec3 q = refinedAt(job.refinedFirst + words[job.limitIndices + k]);
      uint w = job.limitWeights + 3u * k;
      limit += weights[w] * q;
      t1 += weights[w + 1u] * q;
      t2 += weights[w + 2u] * q;
    }
    if ((job.flags & kRefineFlagLimitSurface) != 0u) p = limit;
    if ((job.flags & kRefineFlagLimitNormals) != 0u) n = cross(t1, t2);
  }
  if (!(dot(n, n) > 0.0)) {
    // The refined triangles around the vertex, area weighted.
    uvec2 row = rowOf(job.aroundOffsets, r);
    for (uint k = row.x; k < row.y; ++k) {
      uint c = job.corners + 3u * words[job.aroundTriangles + k];
      vec3 a = refinedAt(job.refinedFirst + words[c]);
      vec3 b = refinedAt(job.refinedFirst + words[c + 1u]);
      vec3 d = refinedAt(job.refinedFirst + words[c + 2u]);
      n += cross(b - a, d - a);
    }
  }
  float len = length(n);
  n = len > 0.0 ? n / len : vec3(0.0, 0.0, 1.0);
  uint o = 3u * (job.outputFirst + v);
  positions[o] = p.x;
  positions[o + 1u] = p.y;
  positions[o + 2u] = p.z;
  normals[o] = n.x;
  normals[o + 1u] = n.y;
  normals[o + 2u] = n.z;
}

void main() {
  uint t = invocationIndex();
  if (t >= pc.count) return;
  RefineJob job = jobs[jobOf(t)];
  if (kStage == kRefineStageRefine) {
    refineVertex(job, t - job.refineBase);
  } else {
    limitVertex(job, t - job.limitBase);
  }
}
