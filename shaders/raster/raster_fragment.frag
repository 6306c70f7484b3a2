// Opaque fragments: Phong, exactly the trace's shading of a primary hit.
// Transmissive fragments: the trace image at this pixel. The compute pass wrote
// it before a barrier; it never leaves the GPU.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../shared/raster.h"
#include "../shared/trace.h"

layout(push_constant) uniform Push { RasterPush pc; };
layout(std430, binding = kRasterBindingMaterials) readonly buffer Materials { GpuMaterial materials[]; };
layout(std430, binding = kRasterBindingTextures) readonly buffer Textures { GpuTexture textures[]; };
layout(std430, binding = kRasterBindingTexels) readonly buffer Texels { uint texels[]; };
layout(std430, binding = kRasterBindingLights) readonly buffer Lights { GpuLight lights[]; };
layout(binding = kRasterBindingTraceImage, rgba16f) uniform readonly image2D traceImage;

#include "../common/shading.glsl"

// The depth pre-pass has settled visibility: each pixel is shaded once.
layout(early_fragment_tests) in;

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inUvs;
layout(location = 3) flat in vec3 inGeometricNormal;
layout(location = 4) flat in uint inMaterial;

layout(location = 0) out vec4 outColour;

void main() {
  if ((pc.flags & kRasterFlagWireframe) != 0u) {
    outColour = pc.wireColor;
    return;
  }
  GpuMaterial m = materials[inMaterial];
  if (m.emissiveFactor.w > 0.0) {
    outColour = vec4(imageLoad(traceImage, ivec2(gl_FragCoord.xy)).rgb, 1.0);
    return;
  }
  vec3 ng = normalize(inGeometricNormal);
  vec3 ns = dot(inNormal, inNormal) > 0.0 ? normalize(inNormal) : ng;
  if (dot(ns, ng) < 0.0) ns = -ns;
  vec3 dir = (pc.flags & kRasterFlagOrthographic) != 0u ? pc.forward.xyz : normalize(inPosition - pc.eye.xyz);
  outColour = vec4(phong(inPosition, ns, inUvs, m, dir, pc.lightCount, pc.forward.xyz), 1.0);
}
