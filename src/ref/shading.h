// Mirrors shaders/common/shading.glsl: texture sampling, materials, lights and
// Phong as shaders/shared/trace.h states them, in double, so that the GPU's
// float shading has an independent ground truth.
#pragma once

#include "scene/scene.h"
#include "shared/trace.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <limits>
#include <vector>

namespace snell::ref::detail {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Defined in prepared_scene.h, which holds this file's textures, materials and lights.
struct TriangleData;
class PreparedScene;

// ---------------------------------------------------------------------------
// Textures

/// One mip level decoded once (sRGB decode per texel, before filtering).
struct LinearLevel {
  int64_t width = 0, height = 0;
  std::vector<glm::dvec4> texels;  // linear RGB and alpha (bytes / 255); row 0 is the image's first row
  std::vector<glm::dvec4> data;    // the same texels as bytes / 255 (data textures: the IOR's, normal maps)
};

/// A texture's mip chain (scene::mipChain, the GPU's rule) decoded.
struct LinearTexture {
  std::vector<LinearLevel> levels;  // empty: unusable, sampled as white
  uint32_t wrapS = gpu::kWrapRepeat, wrapT = gpu::kWrapRepeat;
  bool nearest = false;
};

LinearTexture decode(const scene::Texture& t, bool colour);

/// floor(x) as an integer; NaN and huge values are kept in a range where the
/// conversion is defined (they only arise from broken texture coordinates).
int64_t floorIndex(double x);

// ---------------------------------------------------------------------------
// Materials and lights

struct TextureUse {
  const LinearTexture* texture = nullptr;  // null: white
  int texCoord = 0;
  glm::dmat3 transform{1.0};
  double lodOffset = 0.0;  // scene::textureLodOffset
};

struct ResolvedMaterial {
  glm::dvec3 baseFactor{1.0};
  double baseAlpha = 1.0;  // baseColorFactor.a
  uint32_t alphaMode = gpu::kAlphaOpaque;
  double alphaCutoff = 0.5;
  glm::dvec3 emissiveFactor{0.0};
  TextureUse base, emissive, ior, normal;
  double normalScale = 1.0;
  bool refractive = false;
  double baseIor = 1.5;
  double iorScale = 1.0, iorOffset = 0.0;
  double roughness = 1.0;
  double dispersion = 0.0;
  double priority = 0.0;
  glm::dvec3 attenuationColor{1.0};
  double attenuationDistance = 0.0;  // 0: no volume
};

struct ResolvedLight {
  scene::LightType type = scene::LightType::Directional;
  glm::dvec3 position{0.0};
  glm::dvec3 direction{0.0, 0.0, -1.0};  // the way it shines, unit
  glm::dvec3 radiance{0.0};              // colour * intensity
  double range = kInfinity;
  double cosInner = 1.0, cosOuter = 0.0;
};

// ---------------------------------------------------------------------------
// Tracing

/// Where a ray meets a face: its hit weights and the level of detail per UV
/// set that a texture of lodOffset 0 is read at there.
struct SurfacePoint {
  double b0, b1, b2;
  glm::dvec2 lods;
};

/// The cone's level of detail terms on `tri` (trace.h: Textures).
glm::dvec2 coneLods(const TriangleData& tri, double width, const glm::dvec3& d);

/// The UV `use` reads at `at`: its set's UV through its KHR_texture_transform.
glm::dvec2 textureUv(const TextureUse& use, const TriangleData& tri, const SurfacePoint& at);

/// The texture `use` reads at `at`: colour (sRGB decoded, or data as bytes / 255) and alpha; white without one.
glm::dvec4 textureRgba(const TextureUse& use, const TriangleData& tri, const SurfacePoint& at, bool srgb = true);
glm::dvec3 textureColor(const TextureUse& use, const TriangleData& tri, const SurfacePoint& at, bool srgb = true);

/// How much of an opaque face of `m` is there (trace.h: Alpha) where its base texture's alpha is `textureAlpha`.
double coverageOf(const ResolvedMaterial& m, double textureAlpha);

/// The shading normal `ns` (unit, on Ng's side) bent by `m`'s normal map at
/// `at` (trace.h: Normal maps); `ns` itself without a map or with degenerate UVs.
glm::dvec3 normalMapped(const ResolvedMaterial& m, const TriangleData& tri, const SurfacePoint& at, const glm::dvec3& ns);

/// Light `light` as seen from p: the unit direction towards it and its
/// irradiance; false where it has no direction (a light on the point).
bool lightAt(const ResolvedLight& light, const glm::dvec3& p, glm::dvec3& l, glm::dvec3& e);

glm::dvec3 shadeOpaque(const PreparedScene& prepared, const glm::dvec3& p, const glm::dvec3& shadingNormal,
                       const glm::dvec3& d, const glm::dvec3& base, const glm::dvec3& emissive);

}  // namespace snell::ref::detail
