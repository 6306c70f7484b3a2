// The depth pre-pass of a masked composite: visibility, and a mask of where
// the visible face is transmissive, which the masked trace compacts into its
// pixel list. Depth-tested like the pre-pass, so each pixel keeps the mask of
// its nearest face.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../shared/raster.h"
#include "../shared/trace.h"

layout(early_fragment_tests) in;

layout(std430, binding = kRasterBindingMaterials) readonly buffer Materials { GpuMaterial materials[]; };

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inUvs;
layout(location = 3) flat in vec3 inGeometricNormal;
layout(location = 4) flat in uint inMaterial;

layout(location = 0) out uint outMask;

void main() { outMask = materials[inMaterial].emissiveFactor.w > 0.0 ? 1u : 0u; }
