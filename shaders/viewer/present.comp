// One viewport into the window image: sRGB-encoded composite or heat map,
// then the film gate and the active viewport's outline.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../shared/present.h"
#include "../shared/trace.h"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { PresentPush pc; };
layout(binding = kPresentBindingComposite, rgba16f) uniform readonly image2D composite;
layout(std430, binding = kPresentBindingAov) readonly buffer Aovs { TraceAov aovs[]; };
layout(binding = kPresentBindingOutput, rgba8) uniform writeonly image2D outputImage;

vec3 linearToSrgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, greaterThan(c, vec3(0.0031308)));
}

// Cold to hot: black, blue, magenta, orange, white, already display-referred.
vec3 heat(float t) {
  t = clamp(t, 0.0, 1.0);
  vec3 a = vec3(0.0), b = vec3(0.1, 0.2, 0.9), c = vec3(0.85, 0.15, 0.6), d = vec3(1.0, 0.6, 0.1), e = vec3(1.0);
  if (t < 0.25) return mix(a, b, t / 0.25);
  if (t < 0.5) return mix(b, c, (t - 0.25) / 0.25);
  if (t < 0.75) return mix(c, d, (t - 0.5) / 0.25);
  return mix(d, e, (t - 0.75) / 0.25);
}

void main() {
  uint index = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  uint width = pc.area.z, height = pc.area.w;
  if (index >= width * height) return;
  ivec2 p = ivec2(index % width, index / width);
  vec3 colour;
  if ((pc.flags & kPresentFlagHeatMap) != 0u) {
    colour = heat(float(aovs[index].nodeVisits) / pc.heatMax);
  } else {
    colour = linearToSrgb(imageLoad(composite, p).rgb);
  }
  if ((pc.flags & kPresentFlagGate) != 0u) {
    vec2 c = vec2(p) + 0.5;
    bool inside = c.x >= pc.gate.x && c.x <= pc.gate.z && c.y >= pc.gate.y && c.y <= pc.gate.w;
    bool edge = inside && (c.x - pc.gate.x < 1.0 || pc.gate.z - c.x < 1.0 || c.y - pc.gate.y < 1.0 || pc.gate.w - c.y < 1.0);
    if (!inside) colour *= 0.45;
    if (edge) colour = vec3(0.9, 0.9, 0.3);
  }
  if ((pc.flags & kPresentFlagActive) != 0u &&
      (p.x == 0 || p.y == 0 || p.x == int(width) - 1 || p.y == int(height) - 1)) {
    colour = vec3(0.3, 0.6, 1.0);
  }
  imageStore(outputImage, p + ivec2(pc.area.xy), vec4(colour, 1.0));
}
