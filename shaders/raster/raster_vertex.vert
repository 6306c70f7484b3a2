// Vertex pulling: the triangle's corner from the deformed storage buffers
// (no vertex buffer, no second copy), placed by its instance's transform.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../shared/raster.h"
#include "../common/scene.glsl"
#include "../common/shading.glsl"

layout(push_constant) uniform Push { RasterPush pc; };

layout(location = 0) out vec3 outPosition;  // relative to the frame's origin
layout(location = 1) out vec3 outNormal;    // world space, not normalised
layout(location = 2) out vec4 outUvs;
layout(location = 3) flat out vec3 outGeometricNormal;
layout(location = 4) flat out uint outMaterial;
layout(location = 5) flat out vec2 outDensity;  // uvDensity() of the triangle, per UV set
// The normal map's tangent frame of the triangle (tangentFrame), zero without one.
layout(location = 6) flat out vec3 outTangent;
layout(location = 7) flat out vec3 outBitangent;

void main() {
  uint triangle = uint(gl_VertexIndex) / 3u;
  uint corner = uint(gl_VertexIndex) % 3u;
  GpuInstance inst = instances[gl_InstanceIndex];
  uvec3 i = triangleAt(triangle);
  uint v = i[corner];
  vec4 p = vec4(vertexAt(v), 1.0);
  precise vec3 world = vec3(dot(inst.objectToWorld[0], p), dot(inst.objectToWorld[1], p), dot(inst.objectToWorld[2], p));
  // Normals by the inverse transpose, as the trace does.
  mat3 toWorldNormal = normalToWorld(inst);
  vec3 p0 = vertexAt(i.x), p1 = vertexAt(i.y), p2 = vertexAt(i.z);
  outGeometricNormal = toWorldNormal * cross(p1 - p0, p2 - p0);
  outNormal = toWorldNormal * normalAt(v);
  outUvs = texcoords[v];
  outDensity = uvDensity(vectorToWorld(inst, p1 - p0), vectorToWorld(inst, p2 - p0), texcoords[i.x], texcoords[i.y],
                         texcoords[i.z]);
  outMaterial = inst.material;
  outPosition = world;
  // Every output is written once, outside any branch: Mesa 22.3's llvmpipe
  // at 128-bit vectors (4-lane subgroups: CPUs without AVX, and 64-bit ARM)
  // corrupts the heap drawing any mesh when a vertex shader writes an output
  // inside a branch it keeps (this frame was `if (map && tangentFrame(...))`).
  // The Lavapipe4Lanes tests draw the viewport so.
  GpuTextureSlot normalMap = materials[inst.material].normal;
  vec3 t, b;
  bool framed = tangentFrame(vectorToWorld(inst, p1 - p0), vectorToWorld(inst, p2 - p0),
                             textureUv(normalMap, texcoords[i.x]), textureUv(normalMap, texcoords[i.y]),
                             textureUv(normalMap, texcoords[i.z]), t, b);
  bool mapped = framed && normalMap.texture != kNoTexture;
  outTangent = mapped ? t : vec3(0.0);
  outBitangent = mapped ? b : vec3(0.0);

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
  // A single-sided face seen from behind is not drawn, as the trace passes it
  // (trace.comp: cullSignOf): every corner of it lands outside the view. Its
  // facing is tested in the instance's own space, as the trace tests it, where
  // a mirroring transform turns nothing round.
  vec4 eyeAt = vec4(ortho ? pc.forward.xyz : pc.eye.xyz, ortho ? 0.0 : 1.0);  // a direction, or a point
  vec3 viewer = vec3(dot(inst.worldToObject[0], eyeAt), dot(inst.worldToObject[1], eyeAt), dot(inst.worldToObject[2], eyeAt));
  bool singleSided = (inst.flags & kInstanceCullBackFaces) != 0u;
  bool fromBehind = dot(cross(p1 - p0, p2 - p0), ortho ? viewer : p0 - viewer) > 0.0;
  bool culled = singleSided && fromBehind;
  gl_Position = culled ? vec4(2.0, 2.0, 0.5, 1.0) : vec4(x, y, depth, w);  // perspective: depth = near / z, reverse Z
}
