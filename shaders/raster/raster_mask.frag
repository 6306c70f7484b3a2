// The depth pre-pass of a masked composite: visibility, and a mask of where
// the visible face is transmissive, which the masked trace compacts into its
// pixel list. Depth-tested like the pre-pass, so each pixel keeps the mask of
// its nearest face. With kRasterFlagBehindDepth (glass left out) it keeps the
// nearest face's view depth instead, which the iris-plane lookup starts from.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../shared/raster.h"
#include "../common/scene.glsl"

layout(early_fragment_tests) in;

layout(push_constant) uniform Push { RasterPush pc; };

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inUvs;
layout(location = 3) flat in vec3 inGeometricNormal;
layout(location = 4) flat in uint inMaterial;
layout(location = 5) flat in vec2 inDensity;
layout(location = 6) flat in vec3 inTangent;
layout(location = 7) flat in vec3 inBitangent;

layout(location = 0) out uint outMask;

void main() {
  if ((pc.flags & kRasterFlagBehindDepth) != 0u) {
    bool ortho = (pc.flags & kRasterFlagOrthographic) != 0u;
    // Perspective depth is positive in front of the eye; orthographic depth
    // may not be, so it is kept as the distance from the near plane.
    float z = dot(inPosition - pc.eye.xyz, pc.forward.xyz);
    outMask = floatBitsToUint(max(ortho ? z - pc.forward.w + 1.0 : z, 1e-30));
    return;
  }
  outMask = tracedInViewport(materials[inMaterial]) ? 1u : 0u;
}
