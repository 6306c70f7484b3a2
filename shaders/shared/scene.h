// The scene binding set: what every pass that reads the scene binds, at the
// same slots everywhere (the trace, the driver's ray tracing, the raster
// pass), and the layouts of its records. shaders/common/scene.glsl declares
// these buffers and reads vertices from them; SceneGpu::appendBindings() (with the
// renderer's instances and lights) fills them. A pass's own bindings start at
// kSceneBindingCount.
#ifndef SNELL_SCENE_H
#define SNELL_SCENE_H
#include "shared_types.h"

SNELL_GPU_BEGIN

SNELL_CONST kSceneBindingInstances = 0;   // GpuInstance[] (shared/bvh.h)
SNELL_CONST kSceneBindingPositions = 1;   // float[3 * vertexCount], deformed
SNELL_CONST kSceneBindingNormals = 2;     // float[3 * vertexCount]
SNELL_CONST kSceneBindingTexcoords = 3;   // vec4[vertexCount]: uv0, uv1
SNELL_CONST kSceneBindingIndices = 4;     // uint[3 * triangleCount], absolute
SNELL_CONST kSceneBindingMaterials = 5;   // GpuMaterial[]
SNELL_CONST kSceneBindingLights = 6;      // GpuLight[]
SNELL_CONST kSceneBindingTextures = 7;    // GpuTexture[]
SNELL_CONST kSceneBindingSrgbDecode = 8;  // float[kSrgbDecodeWords]
SNELL_CONST kSceneBindingTexelPages = 9;  // 9 to 9 + kTexelPages - 1: uint[] texel pages
SNELL_CONST kSceneBindingCount = 16;      // a pass's own bindings start here

SNELL_CONST kLightDirectional = 0;
SNELL_CONST kLightPoint = 1;
SNELL_CONST kLightSpot = 2;

SNELL_CONST kWrapRepeat = 0;
SNELL_CONST kWrapMirror = 1;
SNELL_CONST kWrapClamp = 2;

SNELL_CONST kNoTexture = 0xffffffffu;

// A material's use of one texture: which, through which UV set and
// KHR_texture_transform, and how the transform scales a texel's footprint.
// 48 bytes, total: 48 bytes
struct GpuTextureSlot {
  vec4 uvRow0;      // 16: the transform's first row (xyz); w unused
  vec4 uvRow1;      // 16: second row (xyz); w unused
  uint texture;     // 4: index into the texture table; kNoTexture: none
  uint texCoord;    // 4: TEXCOORD_n (0 or 1)
  float lodOffset;  // 4: 0.5 log2(W H |det|) of level 0's size and the transform's 2x2 part (trace.h: Textures)
  uint pad;         // 4
};

// How a face's alpha (baseColorFactor.a times the base texture's alpha) covers it (trace.h: Alpha).
SNELL_CONST kAlphaOpaque = 0u;  // alpha is ignored
SNELL_CONST kAlphaMask = 1u;    // alpha >= alphaCutoff: opaque, else not there
SNELL_CONST kAlphaBlend = 2u;   // alpha of the face's light, 1 - alpha of what lies behind

// 288 bytes, total: 288 bytes
struct GpuMaterial {
  vec4 baseColorFactor;       // 16: rgba, linear
  vec4 emissiveFactor;        // 16: rgb; w unused
  vec4 attenuationColor;      // 16: rgb (KHR_materials_volume); w unused
  float transmission;         // 4: > 0: the face refracts (a boundary of a medium)
  float ior;                  // 4: index of refraction
  float roughness;            // 4: the width of a glass face's highlights
  float dispersion;           // 4: 20 / Abbe number; 0: none
  float priority;             // 4: among overlapping media, larger wins
  float iorScale;             // 4: SNELL_materials_ior_texture: ior + offset + scale * red
  float iorOffset;            // 4
  float attenuationDistance;  // 4: 0: no volume
  GpuTextureSlot base;        // 48: base colour (sRGB)
  GpuTextureSlot emissive;    // 48: emissive (sRGB)
  GpuTextureSlot iorMap;      // 48: the IOR texture (data: bytes / 255)
  GpuTextureSlot normal;      // 48: the tangent-space normal map (data: bytes / 255; trace.h: Normal maps)
  float normalScale;          // 4: the map's x and y are scaled by this
  float alphaCutoff;          // 4: kAlphaMask's threshold
  uint alphaMode;             // 4: kAlpha*
  uint pad0;                  // 4
};

// The sRGB decode table (kSceneBindingSrgbDecode): the linear value of each
// sRGB byte (the reference's double, rounded once), so a texel decodes by
// lookup, as the CPU reference does, rather than by a float pow.
SNELL_CONST kSrgbDecodeWords = 256;

// Texels live in up to kTexelPages storage buffers (pages), each within the
// device's largest storage buffer, so a scene's textures together may exceed
// it. A texture's whole mip chain lies in one page: level 0 (RGBA8, as the
// file stores it, one uint per texel) from firstTexel, each next level (half
// the size, rounded down, at least 1) right after the one before, down to 1x1.
SNELL_CONST kTexelPages = 4;
SNELL_CONST kTextureFlagNearest = 16u;
SNELL_CONST kTextureLevelsShift = 8;   // flags bits 8-12: mip levels
SNELL_CONST kTexturePageShift = 13;    // flags bits 13-15: the page

// 16 bytes, total: 16 bytes
struct GpuTexture {
  uint firstTexel;  // 4: level 0's first texel in its page
  uint width;       // 4: of level 0
  uint height;      // 4
  uint flags;       // 4: bits 0-1 wrap S, 2-3 wrap T, 4 nearest, 8-12 levels, 13-15 page
};

// shaders/comp/texture_mips.comp: one level from the level above, in one page.
// 32 bytes, total: 32 bytes
struct TextureMipPush {
  uint sourceFirst;   // 4: the level above's first texel
  uint sourceWidth;   // 4
  uint sourceHeight;  // 4
  uint targetFirst;   // 4
  uint targetWidth;   // 4
  uint targetHeight;  // 4
  uint srgb;          // 4: 1: averaged in linear light (colour), 0: as bytes (data)
  uint pad;           // 4
};

// 64 bytes, total: 64 bytes
struct GpuLight {
  vec4 positionType;  // 16: camera-relative position, w: kLight* as float
  vec4 direction;     // 16: the way the light shines (unit), w: range (0: infinite)
  vec4 radiance;      // 16: colour * intensity, w unused
  vec4 cone;          // 16: cos inner, cos outer, unused, unused
};

SNELL_GPU_END
#endif
