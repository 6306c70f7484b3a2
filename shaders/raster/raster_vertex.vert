// Vertex pulling: the triangle's corner from the deformed storage buffers
// (no vertex buffer, no second copy), placed by its instance's transform.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../shared/bvh.h"
#include "../shared/raster.h"

layout(push_constant) uniform Push { RasterPush pc; };
layout(std430, binding = kRasterBindingInstances) readonly buffer Instances { GpuInstance instances[]; };
layout(std430, binding = kRasterBindingPositions) readonly buffer Positions { float positions[]; };
layout(std430, binding = kRasterBindingNormals) readonly buffer Normals { float normals[]; };
layout(std430, binding = kRasterBindingTexcoords) readonly buffer Texcoords { vec4 texcoords[]; };
layout(std430, binding = kRasterBindingIndices) readonly buffer Indices { uint indices[]; };

layout(location = 0) out vec3 outPosition;  // relative to the frame's origin
layout(location = 1) out vec3 outNormal;    // world space, not normalised
layout(location = 2) out vec4 outUvs;
layout(location = 3) flat out vec3 outGeometricNormal;
layout(location = 4) flat out uint outMaterial;

vec3 vertexAt(uint v) { return vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]); }

void main() {
  uint triangle = uint(gl_VertexIndex) / 3u;
  uint corner = uint(gl_VertexIndex) % 3u;
  GpuInstance inst = instances[gl_InstanceIndex];
  uint i0 = indices[3u * triangle], i1 = indices[3u * triangle + 1u], i2 = indices[3u * triangle + 2u];
  uint v = corner == 0u ? i0 : (corner == 1u ? i1 : i2);
  vec4 p = vec4(vertexAt(v), 1.0);
  precise vec3 world = vec3(dot(inst.objectToWorld[0], p), dot(inst.objectToWorld[1], p), dot(inst.objectToWorld[2], p));
  // Normals by the inverse transpose, as the trace does.
  // worldToObject holds the rows of W^-1, and mat3() takes columns: this is
  // (W^-1)^T. (It was transposed once more, which is right only when W is
  // symmetric: rotated instances got their normals turned the wrong way.)
  mat3 toWorldNormal = mat3(inst.worldToObject[0].xyz, inst.worldToObject[1].xyz, inst.worldToObject[2].xyz);
  vec3 p0 = vertexAt(i0), p1 = vertexAt(i1), p2 = vertexAt(i2);
  outGeometricNormal = toWorldNormal * cross(p1 - p0, p2 - p0);
  outNormal = toWorldNormal * vec3(normals[3u * v], normals[3u * v + 1u], normals[3u * v + 2u]);
  outUvs = texcoords[v];
  outMaterial = inst.material;
  outPosition = world;

  // precise: the depth pre-pass and the shading pass (EQUAL) must agree on
  // every depth bit, so no compiler may fuse this arithmetic differently in
  // the two pipelines. (`invariant gl_Position` says the same, but Mesa warns
  // about the decoration glslang emits for it.)
  precise vec3 rel = world - pc.eye.xyz;
  precise float z = dot(rel, pc.forward.xyz);
  // The film shift moves the picture: subtract it where the trace adds it to
  // the ray (times z in perspective, where clip x/w is the view's slope).
  bool ortho = (pc.flags & kRasterFlagOrthographic) != 0u;
  precise float w = ortho ? 1.0 : z;
  precise float x = (dot(rel, pc.right.xyz) - pc.shiftX * w) * pc.right.w;
  precise float y = -(dot(rel, pc.up.xyz) - pc.shiftY * w) * pc.up.w;  // Vulkan's y points down the image, as row 0 is the top
  precise float depth = ortho ? clamp((pc.eye.w - z) / (pc.eye.w - pc.forward.w), 0.0, 1.0) : pc.forward.w;
  gl_Position = vec4(x, y, depth, w);  // perspective: depth = near / z, reverse Z, far plane at infinity
}
