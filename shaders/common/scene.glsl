// The scene binding set (shared/scene.h), declared once for every pass that
// reads the scene, and the reads every such pass makes of it.
#ifndef SNELL_SCENE_GLSL
#define SNELL_SCENE_GLSL

#include "../shared/bvh.h"
#include "../shared/scene.h"

layout(std430, binding = kSceneBindingInstances) readonly buffer Instances { GpuInstance instances[]; };
layout(std430, binding = kSceneBindingPositions) readonly buffer Positions { float positions[]; };
layout(std430, binding = kSceneBindingNormals) readonly buffer Normals { float normals[]; };
layout(std430, binding = kSceneBindingTexcoords) readonly buffer Texcoords { vec4 texcoords[]; };
layout(std430, binding = kSceneBindingIndices) readonly buffer Indices { uint indices[]; };
layout(std430, binding = kSceneBindingMaterials) readonly buffer Materials { GpuMaterial materials[]; };
layout(std430, binding = kSceneBindingLights) readonly buffer Lights { GpuLight lights[]; };
layout(std430, binding = kSceneBindingTextures) readonly buffer Textures { GpuTexture textures[]; };
layout(std430, binding = kSceneBindingSrgbDecode) readonly buffer SrgbDecode { float srgbDecode[]; };
// Pages are separate bindings, chosen by a switch rather than an array index:
// indexing an array of buffers per ray needs descriptor indexing, which
// Debian 12's lavapipe does not offer.
layout(std430, binding = kSceneBindingTexelPages) readonly buffer TexelPage0 { uint texelPage0[]; };
layout(std430, binding = kSceneBindingTexelPages + 1) readonly buffer TexelPage1 { uint texelPage1[]; };
layout(std430, binding = kSceneBindingTexelPages + 2) readonly buffer TexelPage2 { uint texelPage2[]; };
layout(std430, binding = kSceneBindingTexelPages + 3) readonly buffer TexelPage3 { uint texelPage3[]; };

vec3 vertexAt(uint v) { return vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]); }
vec3 normalAt(uint v) { return vec3(normals[3u * v], normals[3u * v + 1u], normals[3u * v + 2u]); }
uvec3 triangleAt(uint t) { return uvec3(indices[3u * t], indices[3u * t + 1u], indices[3u * t + 2u]); }

// The instance's rows as a matrix that takes object-space normals to world
// space: worldToObject holds the rows of W^-1 and mat3() takes columns, so
// this is (W^-1)^T, the inverse transpose.
mat3 normalToWorld(GpuInstance inst) {
  return mat3(inst.worldToObject[0].xyz, inst.worldToObject[1].xyz, inst.worldToObject[2].xyz);
}

vec3 pointToWorld(GpuInstance inst, vec3 p) {
  return vec3(dot(inst.objectToWorld[0], vec4(p, 1.0)), dot(inst.objectToWorld[1], vec4(p, 1.0)),
              dot(inst.objectToWorld[2], vec4(p, 1.0)));
}

// A direction or an edge: the linear part only.
vec3 vectorToWorld(GpuInstance inst, vec3 v) {
  return vec3(dot(inst.objectToWorld[0].xyz, v), dot(inst.objectToWorld[1].xyz, v), dot(inst.objectToWorld[2].xyz, v));
}

bool refractive(GpuMaterial m) { return m.transmission > 0.0; }

// A face whose pixels the viewport leaves to the masked trace: glass, and
// opaque faces that alpha may make partly see-through (trace.h: Alpha).
bool tracedInViewport(GpuMaterial m) { return refractive(m) || m.alphaMode != kAlphaOpaque; }

uint texelWord(uint page, uint i) {
  switch (page) {
    case 0u: return texelPage0[i];
    case 1u: return texelPage1[i];
    case 2u: return texelPage2[i];
    default: return texelPage3[i];
  }
}

#endif
