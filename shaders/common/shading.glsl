// Texture sampling and Phong shading as shaders/shared/trace.h states them,
// shared by the trace pass (where a ray lands) and the raster pass (opaque
// fragments), so both draw an opaque face the same way. Textures are
// filtered here, in float, as trace.h states, so the GPU stays within
// rounding of the reference. Include after common/scene.glsl.

#ifndef SNELL_SHADING_GLSL
#define SNELL_SHADING_GLSL
#extension GL_EXT_control_flow_attributes : require

#include "../shared/trace.h"

const float kPi = 3.14159265358979;

vec3 srgbToLinear(uint rgba) {
  return vec3(srgbDecode[rgba & 0xffu], srgbDecode[(rgba >> 8) & 0xffu], srgbDecode[(rgba >> 16) & 0xffu]);
}

// i modulo n, in [0, n): one remainder, whichever sign GLSL's % gives it.
int floorMod(int i, int n) {
  int m = i % n;
  return m < 0 ? m + n : m;
}

int wrapIndex(int i, int size, uint mode) {
  if (mode == kWrapClamp) return clamp(i, 0, size - 1);
  if (mode == kWrapMirror) {
    int period = 2 * size;
    int m = floorMod(i, period);
    return m < size ? m : period - 1 - m;
  }
  return floorMod(i, size);
}

// One mip level of a texture: where it starts in its page and its size.
struct MipLevel {
  uint first;
  int width, height;
};

MipLevel mipLevel(GpuTexture tex, uint level) {
  MipLevel m = MipLevel(tex.firstTexel, int(tex.width), int(tex.height));
  for (uint l = 0u; l < level; ++l) {
    m.first += uint(m.width * m.height);
    m.width = max(m.width / 2, 1);
    m.height = max(m.height / 2, 1);
  }
  return m;
}

// Colour textures are sRGB; data textures (the IOR texture, normal maps) are
// read as bytes / 255. Alpha is always bytes / 255.
vec4 texel(GpuTexture tex, MipLevel m, int x, int y, bool srgb) {
  x = wrapIndex(x, m.width, tex.flags & 3u);
  y = wrapIndex(y, m.height, (tex.flags >> 2) & 3u);
  uint rgba = texelWord(tex.flags >> kTexturePageShift, m.first + uint(y * m.width + x));
  vec4 bytes = vec4(rgba & 0xffu, (rgba >> 8) & 0xffu, (rgba >> 16) & 0xffu, rgba >> 24) / 255.0;
  return srgb ? vec4(srgbToLinear(rgba), bytes.a) : bytes;
}

vec4 bilinear(GpuTexture tex, uint level, vec2 uv, bool srgb) {
  MipLevel m = mipLevel(tex, level);
  vec2 p = uv * vec2(m.width, m.height) - 0.5;
  vec2 base = floor(p);
  vec2 f = p - base;
  int x = int(base.x), y = int(base.y);
  // The four corners from one call site of texel(), rolled (see sampleTexture).
  vec4 top = vec4(0.0), bottom = vec4(0.0), left = vec4(0.0);  // set before the loop, as tracePath's surface is
  [[dont_unroll]] for (int k = 0; k < 4; ++k) {
    vec4 c = texel(tex, m, x + (k & 1), y + (k >> 1), srgb);
    if (k == 1) top = mix(left, c, f.x);
    if (k == 3) bottom = mix(left, c, f.x);
    left = c;
  }
  return mix(top, bottom, f.y);
}

// The texture at uv and level of detail `lod` (trace.h: Textures): trilinear
// between the two levels around it, or the nearest texel of level 0.
vec4 sampleTexture(uint index, vec2 uv, bool srgb, float lod) {
  GpuTexture tex = textures[index];
  if ((tex.flags & kTextureFlagNearest) != 0u) {
    MipLevel m = mipLevel(tex, 0u);
    return texel(tex, m, int(floor(uv.x * float(m.width))), int(floor(uv.y * float(m.height))), srgb);
  }
  uint levels = (tex.flags >> kTextureLevelsShift) & 31u;
  if (!(lod > 0.0)) lod = 0.0;  // magnified, no footprint, or not finite: level 0
  lod = min(lod, float(levels - 1u));
  uint level = uint(lod);
  float f = lod - float(level);
  // Level, then (between two levels) the next one mixed in, from one call
  // site of bilinear(): the trace compiles each site in full, and its
  // compile is what a first image waits for.
  vec4 c = vec4(0.0);
  uint reads = f > 0.0 ? 2u : 1u;
  for (uint k = 0u; k < reads; ++k) {
    vec4 b = bilinear(tex, level + k, uv, srgb);
    c = k == 0u ? b : mix(c, b, f);
  }
  return c;
}

// A lookup's level of detail (trace.h: Textures) comes in two parts: per UV
// set, what a texture of lodOffset 0 is read at on this face (uvDensity, then
// coneLod where the ray's cone meets it), plus the slot's lodOffset.

// 0.5 log2(UV area / world area) of a triangle, per UV set, from its world
// edges e1 = p1 - p0, e2 = p2 - p0 and its corners' UVs.
vec2 uvDensity(vec3 e1, vec3 e2, vec4 uv0, vec4 uv1, vec4 uv2) {
  float world = length(cross(e1, e2));
  vec4 d1 = uv1 - uv0, d2 = uv2 - uv0;
  vec2 uvArea = abs(vec2(d1.x * d2.y - d1.y * d2.x, d1.z * d2.w - d1.w * d2.z));
  return 0.5 * log2(uvArea / world);
}

// The level of detail a cone of `width` meeting the face at cosine `cosine`
// (with its geometric normal) reads a texture of lodOffset 0 at. Past a focus
// a cone's width is negative: its footprint is the width's size.
vec2 coneLod(vec2 density, float width, float cosine) {
  return density + vec2(log2(abs(width)) - log2(abs(cosine)));
}

// The slot's UV set through its KHR_texture_transform.
vec2 textureUv(GpuTextureSlot slot, vec4 uvs) {
  vec3 uv = vec3(slot.texCoord == 1u ? uvs.zw : uvs.xy, 1.0);
  return vec2(dot(slot.uvRow0.xyz, uv), dot(slot.uvRow1.xyz, uv));
}

vec4 textured(GpuTextureSlot slot, vec4 uvs, vec2 lods, bool srgb) {
  if (slot.texture == kNoTexture) return vec4(1.0);
  float lod = (slot.texCoord == 1u ? lods.y : lods.x) + slot.lodOffset;
  return sampleTexture(slot.texture, textureUv(slot, uvs), srgb, lod);
}

vec3 baseColour(GpuMaterial m, vec4 uvs, vec2 lods) {
  return m.baseColorFactor.rgb * textured(m.base, uvs, lods, true).rgb;
}

// The tangent frame a normal map is read in (trace.h: Normal maps): world
// dp/du' and dp/dv'' of the triangle with edges e1, e2 and corner UVs uv0-2
// (the slot's set, transformed), v'' = -v' running up the image; false where
// the UVs are degenerate.
bool tangentFrame(vec3 e1, vec3 e2, vec2 uv0, vec2 uv1, vec2 uv2, out vec3 t, out vec3 b) {
  vec2 d1 = uv1 - uv0, d2 = uv2 - uv0;
  float det = d1.x * d2.y - d2.x * d1.y;
  t = (e1 * d2.y - e2 * d1.y) / det;
  b = -(e2 * d1.x - e1 * d2.x) / det;
  return det != 0.0 && !any(isinf(t)) && !any(isnan(t)) && !any(isinf(b)) && !any(isnan(b));
}

// The shading normal `ns` (unit, on ng's side) bent by a normal map's texel
// (bytes / 255) in the frame (t, b), then turned back to ng's side.
vec3 normalMapped(vec3 ns, vec3 ng, vec3 t, vec3 b, vec3 texel, float scale) {
  vec3 m = (2.0 * texel - 1.0) * vec3(scale, scale, 1.0);
  vec3 tu = t - ns * dot(ns, t);
  if (!(dot(tu, tu) > 0.0)) return ns;
  tu = normalize(tu);
  vec3 bu = cross(ns, tu);
  if (dot(bu, b) < 0.0) bu = -bu;  // a mirrored UV layout flips the bitangent
  vec3 n = m.x * tu + m.y * bu + m.z * ns;
  if (!(dot(n, n) > 0.0)) return ns;
  n = normalize(n);
  return dot(n, ng) < 0.0 ? -n : n;
}

// Light i as seen from `position` (camera-relative): the unit direction
// towards it and the irradiance it brings; lightCount 0 means the headlight
// shining along `headlight`. False where it has no direction (a light on the point).
bool lightAt(uint i, uint lightCount, vec3 headlight, vec3 position, out vec3 l, out vec3 e) {
  l = e = vec3(0.0);  // set on every return, as tracePath's surface is (path.glsl)
  if (lightCount == 0u) {
    l = -headlight;
    e = vec3(kHeadlight);
    return true;
  }
  GpuLight light = lights[i];
  uint type = uint(light.positionType.w);
  if (type == kLightDirectional) {
    l = -light.direction.xyz;
    e = light.radiance.rgb;
    return true;
  }
  vec3 toLight = light.positionType.xyz - position;
  float distance2 = dot(toLight, toLight);
  if (!(distance2 > 0.0)) return false;
  float distance = sqrt(distance2);
  l = toLight / distance;
  e = light.radiance.rgb / distance2;
  float range = light.direction.w;
  if (range > 0.0) {
    float ratio = distance / range;
    float window = clamp(1.0 - ratio * ratio * ratio * ratio, 0.0, 1.0);
    e *= window * window;
  }
  if (type == kLightSpot) {
    float cd = dot(light.direction.xyz, -l);
    float s2 = clamp((cd - light.cone.y) / max(1e-4, light.cone.x - light.cone.y), 0.0, 1.0);
    e *= s2 * s2;
  }
  return true;
}

// Lit colour of a surface point seen along `dir`, in two parts: what it adds
// whatever its base colour texture holds (emissive light, highlights), the
// return value, and `weight`, what that texture's colour is multiplied by
// (ambient and diffuse light times the base colour factor). A baked
// refraction map redraws a landing from these two (TraceAov). `position` is
// camera-relative, `ns` the shading normal, `emissiveTexel` the emissive
// texture's value there (the trace reads it beside the others: phongParts
// reads it itself), `lightCount` lights (0: the headlight shining along
// `headlight`).
vec3 phongLight(vec3 position, vec3 ns, GpuMaterial m, vec3 emissiveTexel, vec3 dir, uint lightCount, vec3 headlight,
                out vec3 weight) {
  vec3 n = dot(ns, dir) > 0.0 ? -ns : ns;  // towards the viewer
  vec3 v = -dir;
  vec3 shine = m.emissiveFactor.rgb * emissiveTexel;
  vec3 diffuse = vec3(kAmbient);
  uint count = max(lightCount, 1u);
  for (uint i = 0u; i < count; ++i) {
    vec3 l, e;
    if (!lightAt(i, lightCount, headlight, position, l, e)) continue;
    float nl = dot(n, l);
    if (nl <= 0.0) continue;
    vec3 h = normalize(l + v);
    diffuse += e * (nl / kPi);
    shine += e * (nl * kSpecular * pow(max(dot(n, h), 0.0), kShininess));
  }
  weight = diffuse * m.baseColorFactor.rgb;
  return shine;
}

// phongLight with the emissive texture read at `uvs` and `lods`, its textures' level of detail.
vec3 phongParts(vec3 position, vec3 ns, vec4 uvs, vec2 lods, GpuMaterial m, vec3 dir, uint lightCount, vec3 headlight,
                out vec3 weight) {
  return phongLight(position, ns, m, textured(m.emissive, uvs, lods, true).rgb, dir, lightCount, headlight, weight);
}

vec3 phong(vec3 position, vec3 ns, vec4 uvs, vec2 lods, GpuMaterial m, vec3 dir, uint lightCount, vec3 headlight) {
  vec3 weight;
  vec3 shine = phongParts(position, ns, uvs, lods, m, dir, lightCount, headlight, weight);
  return shine + weight * textured(m.base, uvs, lods, true).rgb;
}

#endif
