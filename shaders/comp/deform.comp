// The deform pass: morph targets, then linear blend skinning, per vertex, for
// every item listed this frame in one dispatch. Writes the deformed positions
// and normals that the BVH and raster passes read.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../shared/deform.h"

layout(local_size_x_id = kDeformSpecWorkgroupSize) in;

layout(push_constant) uniform Push { DeformPush pc; };
layout(std430, binding = kDeformBindingRestPositions) readonly buffer RestPositions { float restPositions[]; };
layout(std430, binding = kDeformBindingRestNormals) readonly buffer RestNormals { float restNormals[]; };
layout(std430, binding = kDeformBindingMorphDeltas) readonly buffer MorphDeltas { float morphDeltas[]; };
layout(std430, binding = kDeformBindingMorphWeights) readonly buffer MorphWeights { float morphWeights[]; };
layout(std430, binding = kDeformBindingJoints) readonly buffer Joints { uvec4 joints[]; };
layout(std430, binding = kDeformBindingSkinWeights) readonly buffer SkinWeights { vec4 skinWeights[]; };
layout(std430, binding = kDeformBindingJointMatrices) readonly buffer JointMatrices { mat4 jointMatrices[]; };
layout(std430, binding = kDeformBindingPositions) writeonly buffer Positions { float positions[]; };
layout(std430, binding = kDeformBindingNormals) writeonly buffer Normals { float normals[]; };
layout(std430, binding = kDeformBindingJobs) readonly buffer Jobs { DeformJob jobs[]; };

#define JOB_FIRST(i) jobs[i].threadBase
#define JOB_COUNT pc.jobCount
#include "../common/dispatch.glsl"

void main() {
  uint t = invocationIndex();
  if (t >= pc.count) return;
  DeformJob job = jobs[jobOf(t)];
  uint v = t - job.threadBase;

  uint r = 3u * (job.restFirst + v);
  vec3 p = vec3(restPositions[r], restPositions[r + 1u], restPositions[r + 2u]);
  vec3 n = vec3(restNormals[r], restNormals[r + 1u], restNormals[r + 2u]);
  for (uint k = 0u; k < job.targetCount; ++k) {  // bounded by the job
    float w = morphWeights[job.weightFirst + k];
    if (w == 0.0) continue;
    uint i = job.morphFirst + 6u * (k * job.vertexCount + v);
    p += w * vec3(morphDeltas[i], morphDeltas[i + 1u], morphDeltas[i + 2u]);
    n += w * vec3(morphDeltas[i + 3u], morphDeltas[i + 4u], morphDeltas[i + 5u]);
  }
  if (job.jointCount > 0u) {
    // The loader checked joint indices against the skin; the clamp keeps a
    // corrupted buffer from reading outside the item's matrices anyway.
    uvec4 j = job.jointFirst + min(joints[job.skinFirst + v], uvec4(job.jointCount - 1u));
    vec4 w = skinWeights[job.skinFirst + v];
    mat4 m = w.x * jointMatrices[j.x] + w.y * jointMatrices[j.y] + w.z * jointMatrices[j.z] + w.w * jointMatrices[j.w];
    p = (m * vec4(p, 1.0)).xyz;
    // Cofactor (det * inverse-transpose), sign-corrected as in src/scene/evaluate.cpp.
    mat3 a = mat3(m);
    mat3 cofactor = mat3(cross(a[1], a[2]), cross(a[2], a[0]), cross(a[0], a[1]));
    n = cofactor * n * (determinant(a) < 0.0 ? -1.0 : 1.0);
  }
  float len = length(n);
  n = len > 0.0 ? n / len : n;
  uint o = 3u * (job.outputFirst + v);
  positions[o] = p.x;
  positions[o + 1u] = p.y;
  positions[o + 2u] = p.z;
  normals[o] = n.x;
  normals[o + 1u] = n.y;
  normals[o + 2u] = n.z;
}
