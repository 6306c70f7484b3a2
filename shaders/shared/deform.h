// Layout shared by shaders/comp/deform.comp and src/render/deform_pass.cpp.
// One dispatch deforms every item that changed in a frame: each item is a
// job, and the invocations of a job are its vertices.
#ifndef SNELL_DEFORM_H
#define SNELL_DEFORM_H
#include "shared_types.h"

SNELL_GPU_BEGIN

// Binding slots of set 0. Positions and normals are packed float triples
// (12 bytes a vertex), the layout the BVH builder reads. The rest pose, morph
// deltas and skin data of every deforming shape sit one after another.
SNELL_CONST kDeformBindingRestPositions = 0;  // float[3 * vertices]
SNELL_CONST kDeformBindingRestNormals = 1;    // float[3 * vertices]
SNELL_CONST kDeformBindingMorphDeltas = 2;    // float[6 * targets * vertices]: (dp, dn) per target, then vertex
SNELL_CONST kDeformBindingMorphWeights = 3;   // float[]: this frame's weights, job after job
SNELL_CONST kDeformBindingJoints = 4;         // uvec4[skinned vertices]
SNELL_CONST kDeformBindingSkinWeights = 5;    // vec4[skinned vertices], summing to 1
SNELL_CONST kDeformBindingJointMatrices = 6;  // mat4[]: this frame's joint world * inverse bind, moved to each item's anchor
SNELL_CONST kDeformBindingPositions = 7;      // float[3 * vertexCount], out
SNELL_CONST kDeformBindingNormals = 8;        // float[3 * vertexCount], out
SNELL_CONST kDeformBindingJobs = 9;           // DeformJob[jobCount]

SNELL_CONST kDeformSpecWorkgroupSize = 0;

// One deforming item of this frame.
// 48 bytes, total: 48 bytes
struct DeformJob {
  uint threadBase;   // 4: its first invocation
  uint vertexCount;  // 4
  uint restFirst;    // 4: its shape's first vertex in the rest buffers
  uint outputFirst;  // 4: where its deformed vertices go
  uint morphFirst;   // 4: its shape's first float in the morph deltas
  uint targetCount;  // 4: morph targets; 0 skips morphing
  uint weightFirst;  // 4: its first weight this frame
  uint skinFirst;    // 4: its shape's first skinned vertex
  uint jointFirst;   // 4: its first joint matrix this frame
  uint jointCount;   // 4: 0 skips skinning
  uint pad0;         // 4
  uint pad1;         // 4
};

// 16 bytes, total: 16 bytes
struct DeformPush {
  uint count;     // 4: invocations (vertices of every job)
  uint jobCount;  // 4
  uint pad0;      // 4
  uint pad1;      // 4
};

SNELL_GPU_END
#endif
