// Texture sampling and Phong shading as shaders/shared/trace.h states them,
// shared by the trace pass (where a ray lands) and the raster pass (opaque
// fragments), so both draw an opaque face the same way. The including shader
// declares the readonly buffer `lights` (GpuLight[]) and defines the binding
// slots of the texture table, the sRGB decode table and the first texel page
// (SNELL_BINDING_TEXTURES, SNELL_BINDING_SRGB_DECODE, SNELL_BINDING_TEXEL_PAGES).

#ifndef SNELL_SHADING_GLSL
#define SNELL_SHADING_GLSL

layout(std430, binding = SNELL_BINDING_TEXTURES) readonly buffer Textures { GpuTexture textures[]; };
layout(std430, binding = SNELL_BINDING_SRGB_DECODE) readonly buffer SrgbDecode { float srgbDecode[]; };
// Pages are separate bindings, chosen by a switch rather than an array index:
// indexing an array of buffers per ray needs descriptor indexing, which
// Debian 12's lavapipe does not offer. Texels are filtered here, in float, as
// trace.h states, so the GPU stays within rounding of the reference.
layout(std430, binding = SNELL_BINDING_TEXEL_PAGES) readonly buffer TexelPage0 { uint texelPage0[]; };
layout(std430, binding = SNELL_BINDING_TEXEL_PAGES + 1) readonly buffer TexelPage1 { uint texelPage1[]; };
layout(std430, binding = SNELL_BINDING_TEXEL_PAGES + 2) readonly buffer TexelPage2 { uint texelPage2[]; };
layout(std430, binding = SNELL_BINDING_TEXEL_PAGES + 3) readonly buffer TexelPage3 { uint texelPage3[]; };

uint texelWord(uint page, uint i) {
  switch (page) {
    case 0u: return texelPage0[i];
    case 1u: return texelPage1[i];
    case 2u: return texelPage2[i];
    default: return texelPage3[i];
  }
}

const float kPi = 3.14159265358979;

vec3 srgbToLinear(uint rgba) {
  return vec3(srgbDecode[rgba & 0xffu], srgbDecode[(rgba >> 8) & 0xffu], srgbDecode[(rgba >> 16) & 0xffu]);
}

int wrapIndex(int i, int size, uint mode) {
  if (mode == kWrapClamp) return clamp(i, 0, size - 1);
  if (mode == kWrapMirror) {
    int period = 2 * size;
    int m = ((i % period) + period) % period;
    return m < size ? m : period - 1 - m;
  }
  return ((i % size) + size) % size;
}

// Colour textures are sRGB; data textures (the IOR's) are read as bytes / 255.
vec3 texel(GpuTexture tex, int x, int y, bool srgb) {
  x = wrapIndex(x, int(tex.width), tex.flags & 3u);
  y = wrapIndex(y, int(tex.height), (tex.flags >> 2) & 3u);
  uint rgba = texelWord(tex.flags >> kTexturePageShift, tex.firstTexel + uint(y) * tex.width + uint(x));
  return srgb ? srgbToLinear(rgba) : vec3(rgba & 0xffu, (rgba >> 8) & 0xffu, (rgba >> 16) & 0xffu) / 255.0;
}

vec3 sampleTexture(uint index, vec2 uv, bool srgb) {
  GpuTexture tex = textures[index];
  if ((tex.flags & kTextureFlagNearest) != 0u) {
    return texel(tex, int(floor(uv.x * float(tex.width))), int(floor(uv.y * float(tex.height))), srgb);
  }
  vec2 p = uv * vec2(tex.width, tex.height) - 0.5;
  vec2 base = floor(p);
  vec2 f = p - base;
  int x = int(base.x), y = int(base.y);
  vec3 top = mix(texel(tex, x, y, srgb), texel(tex, x + 1, y, srgb), f.x);
  vec3 bottom = mix(texel(tex, x, y + 1, srgb), texel(tex, x + 1, y + 1, srgb), f.x);
  return mix(top, bottom, f.y);
}

vec3 textured(uint texture, vec4 uvs, uint texCoord, vec4 row0, vec4 row1, bool srgb) {
  if (texture == kNoTexture) return vec3(1.0);
  vec3 uv = vec3(texCoord == 1u ? uvs.zw : uvs.xy, 1.0);
  return sampleTexture(texture, vec2(dot(row0.xyz, uv), dot(row1.xyz, uv)), srgb);
}

vec3 textured(uint texture, vec4 uvs, uint texCoord, vec4 row0, vec4 row1) {
  return textured(texture, uvs, texCoord, row0, row1, true);
}

vec3 baseColour(GpuMaterial m, vec4 uvs) {
  return m.baseColorFactor.rgb * textured(m.textures.x, uvs, m.textures.y, m.baseUvRow0, m.baseUvRow1);
}

// Light i as seen from `position` (camera-relative): the unit direction
// towards it and the irradiance it brings; lightCount 0 means the headlight
// shining along `headlight`. False where it has no direction (a light on the point).
bool lightAt(uint i, uint lightCount, vec3 headlight, vec3 position, out vec3 l, out vec3 e) {
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

// Lit colour of a surface point seen along `dir`: `position` camera-relative,
// `ns` the shading normal, `lightCount` lights (0: the headlight shining along
// `headlight`).
vec3 phong(vec3 position, vec3 ns, vec4 uvs, GpuMaterial m, vec3 dir, uint lightCount, vec3 headlight) {
  vec3 base = baseColour(m, uvs);
  vec3 n = dot(ns, dir) > 0.0 ? -ns : ns;  // towards the viewer
  vec3 v = -dir;
  vec3 colour = m.emissiveFactor.rgb * textured(m.textures.z, uvs, m.textures.w, m.emissiveUvRow0, m.emissiveUvRow1) +
                kAmbient * base;
  uint count = max(lightCount, 1u);
  for (uint i = 0u; i < count; ++i) {
    vec3 l, e;
    if (!lightAt(i, lightCount, headlight, position, l, e)) continue;
    float nl = dot(n, l);
    if (nl <= 0.0) continue;
    vec3 h = normalize(l + v);
    colour += e * nl * (base / kPi + kSpecular * pow(max(dot(n, h), 0.0), kShininess));
  }
  return colour;
}

#endif
