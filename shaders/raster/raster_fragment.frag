// Opaque fragments: Phong, exactly the trace's shading of a primary hit.
// Transmissive fragments, and those alpha may make see-through: the trace
// image at this pixel (where nothing was traced, alpha is ignored). The compute pass wrote
// it before a barrier; it never leaves the GPU. With a screen-space method
// the "trace image" is the picture of what lies behind the glass, read at a
// pixel displaced the way the method says, and tinted by the glass once.
// With a baked refraction map, the baked pixel at this place on the screen.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../shared/raster.h"
#include "../common/scene.glsl"
#include "../common/shading.glsl"

layout(push_constant) uniform Push { RasterPush pc; };
layout(binding = kRasterBindingTraceImage, rgba16f) uniform readonly image2D traceImage;
layout(binding = kRasterBindingBehindDepth, r32ui) uniform readonly uimage2D behindDepth;
layout(std430, binding = kRasterBindingRefractionMap) readonly buffer RefractionMap { RefractionTexel refractionMap[]; };

// The depth pre-pass has settled visibility: each pixel is shaded once.
layout(early_fragment_tests) in;

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inUvs;
layout(location = 3) flat in vec3 inGeometricNormal;
layout(location = 4) flat in uint inMaterial;
layout(location = 5) flat in vec2 inDensity;
layout(location = 6) flat in vec3 inTangent;
layout(location = 7) flat in vec3 inBitangent;

layout(location = 0) out vec4 outColour;

// A point relative to the frame origin to its pixel (the vertex shader's projection).
vec2 pixelOf(vec3 p, vec2 size) {
  vec3 rel = p - pc.eye.xyz;
  bool ortho = (pc.flags & kRasterFlagOrthographic) != 0u;
  float w = ortho ? 1.0 : dot(rel, pc.forward.xyz);
  float x = (dot(rel, pc.right.xyz) - pc.shiftX * w) * pc.right.w / w;
  float y = -(dot(rel, pc.up.xyz) - pc.shiftY * w) * pc.up.w / w;
  return (vec2(x, y) * 0.5 + 0.5) * size;
}

// Where the refracted ray meets the plane facing the camera through what lies
// straight behind this pixel: the game engines' iris plane, placed from the
// picture behind the glass rather than from an eye rig.
vec2 irisPlaneLookup(vec3 dir, vec3 ns, float ior, vec2 size) {
  uint bits = imageLoad(behindDepth, ivec2(gl_FragCoord.xy)).r;
  if (bits == 0u) return gl_FragCoord.xy;  // nothing behind: the background either way
  bool ortho = (pc.flags & kRasterFlagOrthographic) != 0u;
  float behind = uintBitsToFloat(bits) - (ortho ? 1.0 - pc.forward.w : 0.0);
  vec3 n = dot(ns, dir) > 0.0 ? -ns : ns;
  vec3 t = refract(dir, n, 1.0 / ior);
  float along = dot(t, pc.forward.xyz);
  float gap = behind - dot(inPosition - pc.eye.xyz, pc.forward.xyz);
  if (dot(t, t) == 0.0 || along <= 0.0 || gap <= 0.0) return gl_FragCoord.xy;
  return pixelOf(inPosition + t * (gap / along), size);
}

// The baked pixel at this fragment's place on the screen (nearest: a map
// is never filtered, that would crack it), redrawn from its two parts.
vec3 refractionMapLookup(vec2 size) {
  uvec2 mapSize = uvec2(pc.mapWidth, pc.mapHeight);
  uvec2 at = min(uvec2(gl_FragCoord.xy * vec2(mapSize) / size), mapSize - 1u);
  RefractionTexel t = refractionMap[at.y * mapSize.x + at.x];
  vec3 texel = vec3(1.0);
  if (t.material != kNoHit) {
    uint texture = materials[t.material].base.texture;
    if (texture != kNoTexture) texel = sampleTexture(texture, vec2(t.u, t.v), true, t.weight.w).rgb;
  }
  return t.shine.rgb + t.weight.rgb * texel;
}

void main() {
  if ((pc.flags & kRasterFlagWireframe) != 0u) {
    outColour = pc.wireColor;
    return;
  }
  GpuMaterial m = materials[inMaterial];
  vec3 ng = normalize(inGeometricNormal);
  vec3 ns = dot(inNormal, inNormal) > 0.0 ? normalize(inNormal) : ng;
  if (dot(ns, ng) < 0.0) ns = -ns;
  bool ortho = (pc.flags & kRasterFlagOrthographic) != 0u;
  vec3 dir = ortho ? pc.forward.xyz : normalize(inPosition - pc.eye.xyz);
  // The primary ray's cone, as the trace starts it (trace.h: Textures).
  float height = float(imageSize(traceImage).y);
  float width = ortho ? 2.0 / (pc.up.w * height) : atan(2.0 / (pc.up.w * height)) * length(inPosition - pc.eye.xyz);
  vec2 lods = coneLod(inDensity, width, dot(dir, ng));
  if (dot(inTangent, inTangent) > 0.0) {
    ns = normalMapped(ns, ng, inTangent, inBitangent, textured(m.normal, inUvs, lods, false).rgb, m.normalScale);
  }
  if (!refractive(m) && tracedInViewport(m) && (pc.flags & kRasterFlagTraced) != 0u) {
    // A face alpha may make see-through: the trace drew what shows at this pixel.
    outColour = vec4(imageLoad(traceImage, ivec2(gl_FragCoord.xy)).rgb, 1.0);
    return;
  }
  if (refractive(m)) {
    if ((pc.flags & kRasterFlagRefractionMap) != 0u) {
      outColour = vec4(refractionMapLookup(vec2(imageSize(traceImage))), 1.0);
      return;
    }
    if ((pc.flags & (kRasterFlagNormalOffset | kRasterFlagIrisPlane)) == 0u) {
      outColour = vec4(imageLoad(traceImage, ivec2(gl_FragCoord.xy)).rgb, 1.0);
      return;
    }
    vec2 size = vec2(imageSize(traceImage));
    vec2 at = gl_FragCoord.xy;
    if ((pc.flags & kRasterFlagNormalOffset) != 0u) {
      // Refraction bends the view towards the inward normal: look up against the normal's screen direction.
      at -= pc.offsetStrength * size.y * vec2(dot(ns, pc.right.xyz), -dot(ns, pc.up.xyz));
    } else {
      at = irisPlaneLookup(dir, ns, m.ior, size);
    }
    ivec2 texel = clamp(ivec2(floor(at)), ivec2(0), ivec2(size) - 1);
    outColour = vec4(imageLoad(traceImage, texel).rgb * baseColour(m, inUvs, lods), 1.0);
    return;
  }
  outColour = vec4(phong(inPosition, ns, inUvs, lods, m, dir, pc.lightCount, pc.forward.xyz), 1.0);
}
