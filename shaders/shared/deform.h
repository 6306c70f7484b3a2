// Layout shared by shaders/comp/deform.comp and src/render/deform_pass.cpp.
#ifndef SNELL_DEFORM_H
#define SNELL_DEFORM_H
#include "shared_types.h"

SNELL_GPU_BEGIN

// Binding slots of set 0. Positions and normals are packed float triples
// (12 bytes a vertex), the layout the BVH builder reads.
SNELL_CONST kDeformBindingRestPositions = 0;  // float[3 * vertexCount]
SNELL_CONST kDeformBindingRestNormals = 1;    // float[3 * vertexCount]
SNELL_CONST kDeformBindingMorphDeltas = 2;    // float[6 * targetCount * vertexCount]: (dp, dn) per target, then vertex
SNELL_CONST kDeformBindingMorphWeights = 3;   // float[targetCount]
SNELL_CONST kDeformBindingJoints = 4;         // uvec4[vertexCount]
SNELL_CONST kDeformBindingSkinWeights = 5;    // vec4[vertexCount], summing to 1
SNELL_CONST kDeformBindingJointMatrices = 6;  // mat4[jointCount]: joint world * inverse bind
SNELL_CONST kDeformBindingPositions = 7;      // float[3 * vertexCount], out
SNELL_CONST kDeformBindingNormals = 8;        // float[3 * vertexCount], out

SNELL_CONST kDeformSpecWorkgroupSize = 0;

// 16 bytes, total: 16 bytes
struct DeformPush {
  uint vertexCount;  // 4
  uint targetCount;  // 4: morph targets; 0 skips morphing
  uint jointCount;   // 4: 0 skips skinning
  uint outputFirst;  // 4: first output vertex (outputs are slices of shared buffers)
};

SNELL_GPU_END
#endif
