// Mirrors shaders/common/shading.glsl's filtering and lighting: trace.h's
// texture and Phong rules are written twice, here and there, so each checks the other.
#include "ref/shading.h"

#include "ref/prepared_scene.h"
#include "scene/texture_mips.h"

#include <algorithm>
#include <cmath>

namespace snell::ref::detail {

namespace {

// The contract's constants are floats; the reference uses exactly those values.
constexpr double kAmbient = double(gpu::kAmbient);
constexpr double kSpecular = double(gpu::kSpecular);
constexpr double kShininess = double(gpu::kShininess);

uint32_t wrapMode(bool repeat, bool mirror) {
  if (mirror) return gpu::kWrapMirror;
  return repeat ? gpu::kWrapRepeat : gpu::kWrapClamp;
}

// i modulo n, in [0, n).
int64_t floorMod(int64_t i, int64_t n) {
  int64_t m = i % n;
  return m < 0 ? m + n : m;
}

int64_t wrapIndex(int64_t i, int64_t n, uint32_t mode) {
  if (mode == gpu::kWrapClamp) return std::clamp<int64_t>(i, 0, n - 1);
  if (mode == gpu::kWrapMirror) {
    int64_t m = floorMod(i, 2 * n);
    return m < n ? m : 2 * n - 1 - m;
  }
  return floorMod(i, n);
}

glm::dvec4 bilinear(const LinearTexture& t, size_t level, const glm::dvec2& uv, bool srgb) {
  const LinearLevel& l = t.levels[level];
  const std::vector<glm::dvec4>& texels = srgb ? l.texels : l.data;
  auto texel = [&](int64_t x, int64_t y) {
    return texels[size_t(wrapIndex(y, l.height, t.wrapT) * l.width + wrapIndex(x, l.width, t.wrapS))];
  };
  double x = uv.x * double(l.width) - 0.5, y = uv.y * double(l.height) - 0.5;
  int64_t x0 = floorIndex(x), y0 = floorIndex(y);
  double fx = std::clamp(x - double(x0), 0.0, 1.0), fy = std::clamp(y - double(y0), 0.0, 1.0);
  glm::dvec4 top = glm::mix(texel(x0, y0), texel(x0 + 1, y0), fx);
  glm::dvec4 bottom = glm::mix(texel(x0, y0 + 1), texel(x0 + 1, y0 + 1), fx);
  return glm::mix(top, bottom, fy);
}

/// The texture at uv and level of detail `lod` (trace.h: Textures).
glm::dvec4 sample(const LinearTexture& t, const glm::dvec2& uv, bool srgb, double lod) {
  if (t.nearest) {
    const LinearLevel& l = t.levels[0];
    const std::vector<glm::dvec4>& texels = srgb ? l.texels : l.data;
    int64_t x = wrapIndex(floorIndex(uv.x * double(l.width)), l.width, t.wrapS);
    int64_t y = wrapIndex(floorIndex(uv.y * double(l.height)), l.height, t.wrapT);
    return texels[size_t(y * l.width + x)];
  }
  if (!(lod > 0.0)) lod = 0.0;  // magnified, no footprint, or not finite: level 0
  lod = std::min(lod, double(t.levels.size() - 1));
  const size_t level = size_t(lod);
  const double f = lod - double(level);
  glm::dvec4 c = bilinear(t, level, uv, srgb);
  if (f > 0.0) c = glm::mix(c, bilinear(t, level + 1, uv, srgb), f);
  return c;
}

}  // namespace

LinearTexture decode(const scene::Texture& t, bool colour) {
  LinearTexture out;
  double table[256];
  for (int v = 0; v < 256; ++v) table[v] = scene::srgbToLinear(uint8_t(v));
  for (const scene::MipLevel& level : scene::mipChain(t, colour)) {
    LinearLevel l;
    l.width = level.width;
    l.height = level.height;
    const size_t count = size_t(level.width) * level.height;
    l.texels.resize(count);
    l.data.resize(count);
    for (size_t i = 0; i < count; ++i) {
      const uint8_t* rgba = &level.rgba[i * 4];
      l.texels[i] = {table[rgba[0]], table[rgba[1]], table[rgba[2]], rgba[3] / 255.0};
      l.data[i] = glm::dvec4(rgba[0], rgba[1], rgba[2], rgba[3]) / 255.0;
    }
    out.levels.push_back(std::move(l));
  }
  out.wrapS = wrapMode(t.repeatS, t.mirrorS);
  out.wrapT = wrapMode(t.repeatT, t.mirrorT);
  out.nearest = !t.linearFilter;
  return out;
}

int64_t floorIndex(double x) {
  if (!(x == x)) return 0;
  return int64_t(std::floor(std::clamp(x, -1e15, 1e15)));
}

glm::dvec2 coneLods(const TriangleData& tri, double width, const glm::dvec3& d) {
  const double footprint = std::log2(std::abs(width)) - std::log2(std::abs(glm::dot(d, tri.ng)));
  return {tri.density[0] + footprint, tri.density[1] + footprint};
}

glm::dvec2 textureUv(const TextureUse& use, const TriangleData& tri, const SurfacePoint& at) {
  glm::dvec2 uv(0.0);
  if (use.texCoord == 0 || use.texCoord == 1) {
    const glm::dvec2* set = tri.uv[use.texCoord];
    uv = at.b0 * set[0] + at.b1 * set[1] + at.b2 * set[2];
  }
  return glm::dvec2(use.transform * glm::dvec3(uv, 1.0));
}

glm::dvec4 textureRgba(const TextureUse& use, const TriangleData& tri, const SurfacePoint& at, bool srgb) {
  if (!use.texture) return glm::dvec4(1.0);
  const double lod = (use.texCoord == 1 ? at.lods.y : at.lods.x) + use.lodOffset;
  return sample(*use.texture, textureUv(use, tri, at), srgb, lod);
}

glm::dvec3 textureColor(const TextureUse& use, const TriangleData& tri, const SurfacePoint& at, bool srgb) {
  return glm::dvec3(textureRgba(use, tri, at, srgb));
}

double coverageOf(const ResolvedMaterial& m, double textureAlpha) {
  const double alpha = m.baseAlpha * textureAlpha;
  if (m.alphaMode == gpu::kAlphaMask) return alpha >= m.alphaCutoff ? 1.0 : 0.0;
  if (m.alphaMode == gpu::kAlphaBlend) return std::clamp(alpha, 0.0, 1.0);
  return 1.0;
}

glm::dvec3 normalMapped(const ResolvedMaterial& m, const TriangleData& tri, const SurfacePoint& at, const glm::dvec3& ns) {
  if (!m.normal.texture) return ns;
  // The frame: world dp/du' and dp/dv'' with v'' = -v' running up the image,
  // from the corners' UVs in the map's set through its transform.
  glm::dvec2 uv[3];
  for (int c = 0; c < 3; ++c) {
    SurfacePoint corner{c == 0 ? 1.0 : 0.0, c == 1 ? 1.0 : 0.0, c == 2 ? 1.0 : 0.0, at.lods};
    uv[c] = textureUv(m.normal, tri, corner);
  }
  const glm::dvec3 e1 = tri.v[1] - tri.v[0], e2 = tri.v[2] - tri.v[0];
  const glm::dvec2 d1 = uv[1] - uv[0], d2 = uv[2] - uv[0];
  const double det = d1.x * d2.y - d2.x * d1.y;
  if (det == 0.0) return ns;
  const glm::dvec3 t = (e1 * d2.y - e2 * d1.y) / det, b = -(e2 * d1.x - e1 * d2.x) / det;
  glm::dvec3 tu = unitOrZero(t - ns * glm::dot(ns, t));
  if (tu == glm::dvec3(0.0) || !std::isfinite(glm::dot(b, b))) return ns;
  glm::dvec3 bu = glm::cross(ns, tu);
  if (glm::dot(bu, b) < 0.0) bu = -bu;  // a mirrored UV layout flips the bitangent
  const glm::dvec3 texel = textureColor(m.normal, tri, at, false);
  const glm::dvec3 v = (2.0 * texel - 1.0) * glm::dvec3(m.normalScale, m.normalScale, 1.0);
  glm::dvec3 n = unitOrZero(v.x * tu + v.y * bu + v.z * ns);
  if (n == glm::dvec3(0.0)) return ns;
  return glm::dot(n, tri.ng) < 0.0 ? -n : n;
}

bool lightAt(const ResolvedLight& light, const glm::dvec3& p, glm::dvec3& l, glm::dvec3& e) {
  if (light.type == scene::LightType::Directional) {
    l = -light.direction;
    e = light.radiance;
    return true;
  }
  glm::dvec3 toLight = light.position - p;
  double distance = glm::length(toLight);
  if (!(distance > 0.0)) return false;
  l = toLight / distance;
  double window = 1.0;
  if (std::isfinite(light.range)) {
    double ratio = distance / light.range;
    window = std::clamp(1.0 - ratio * ratio * ratio * ratio, 0.0, 1.0);
    window *= window;
  }
  e = light.radiance / (distance * distance) * window;
  if (light.type == scene::LightType::Spot) {
    double s = std::clamp((glm::dot(light.direction, -l) - light.cosOuter) / std::max(1e-4, light.cosInner - light.cosOuter),
                          0.0, 1.0);
    e *= s * s;
  }
  return true;
}

glm::dvec3 shadeOpaque(const PreparedScene& prepared, const glm::dvec3& p, const glm::dvec3& shadingNormal,
                       const glm::dvec3& d, const glm::dvec3& base, const glm::dvec3& emissive) {
  const glm::dvec3 v = -d;
  const glm::dvec3 n = glm::dot(shadingNormal, v) < 0.0 ? -shadingNormal : shadingNormal;
  glm::dvec3 sum(0.0);
  for (const ResolvedLight& light : prepared.lights()) {
    glm::dvec3 l, e;
    if (!lightAt(light, p, l, e)) continue;
    double nDotL = glm::dot(n, l);
    // Also covers l = -v, where H would be undefined (n faces v, so n.l <= 0).
    if (!(nDotL > 0.0)) continue;
    glm::dvec3 h = glm::normalize(l + v);
    double specular = kSpecular * std::pow(std::max(glm::dot(n, h), 0.0), kShininess);
    sum += e * nDotL * (base / kPi + specular);
  }
  return emissive + kAmbient * base + sum;
}

}  // namespace snell::ref::detail
