#include "bake/refraction_bake.h"

#include "vk/commands.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace snell::bake {

namespace {

// A coordinate wrapped into [0, 1] the way a sampler wraps it.
double wrapped(double x, bool repeat, bool mirror) {
  if (mirror) {
    double t = x - 2.0 * std::floor(x / 2.0);
    return t > 1.0 ? 2.0 - t : t;
  }
  if (repeat) return x - std::floor(x);
  return std::clamp(x, 0.0, 1.0);
}

constexpr uint16_t kHalf16 = 32768;
constexpr uint8_t kHalf8 = 128;

}  // namespace

std::string describe(const RefractionBake& bake, const scene::Scene& scene) {
  size_t lands = bake.count(Coverage::Lands), marked = bake.count(Coverage::Marked);
  std::string text = std::to_string(lands + marked) + " glass pixels";
  if (bake.behindMaterial == gpu::kNoHit) return text + ", none of them over a textured surface";
  const scene::Material& m = scene.materials.at(bake.behindMaterial);
  const scene::Texture& t = scene.textures.at(size_t(m.baseColorTexture.texture));
  auto named = [](const std::string& name, uint32_t index) {
    return name.empty() ? "#" + std::to_string(index) : "'" + name + "'";
  };
  return text + "; " + std::to_string(lands) + " land on material " + named(m.name, bake.behindMaterial) +
         " (its texture " + named(t.name, uint32_t(m.baseColorTexture.texture)) + ", " + std::to_string(t.width) + "x" +
         std::to_string(t.height) + "), " + std::to_string(marked) + " marked (no texel of it behind)";
}

glm::dvec2 storedUv(const RefractionBake& bake, size_t pixel, const scene::Scene& scene) {
  const gpu::RefractionTexel& t = bake.texels[pixel];
  int texture = scene.materials.at(t.material).baseColorTexture.texture;
  const scene::Texture& tex = scene.textures.at(size_t(texture));
  return {wrapped(t.u, tex.repeatS, tex.mirrorS), wrapped(t.v, tex.repeatT, tex.mirrorT)};
}

std::optional<Encoding> encodingFromName(std::string_view name) {
  if (name == "rg16") return Encoding::Rg16;
  if (name == "exr") return Encoding::Exr;
  if (name == "sky8") return Encoding::Sky8;
  return std::nullopt;
}

const char* encodingName(Encoding encoding) {
  switch (encoding) {
    case Encoding::Rg16: return "rg16";
    case Encoding::Exr: return "exr";
    case Encoding::Sky8: return "sky8";
  }
  return "?";
}

DecodedMap storedMap(const RefractionBake& bake, const scene::Scene& scene) {
  DecodedMap map;
  map.width = bake.width;
  map.height = bake.height;
  map.coverage.resize(bake.texels.size());
  map.uv.resize(bake.texels.size(), glm::dvec2(std::numeric_limits<double>::quiet_NaN()));
  for (size_t i = 0; i < bake.texels.size(); ++i) {
    map.coverage[i] = bake.coverage(i);
    if (map.coverage[i] == Coverage::Lands) map.uv[i] = storedUv(bake, i, scene);
  }
  return map;
}

MapPixels encodeMap(const DecodedMap& map, Encoding encoding) {
  MapPixels out;
  out.width = map.width;
  out.height = map.height;
  size_t n = map.coverage.size();
  if (encoding == Encoding::Rg16) out.rg16.assign(4 * n, 0);
  if (encoding == Encoding::Exr) out.rgba32f.assign(4 * n, 0.0f);
  if (encoding == Encoding::Sky8) out.sky8.assign(4 * n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (map.coverage[i] == Coverage::Empty) continue;
    bool lands = map.coverage[i] == Coverage::Lands;
    glm::dvec2 uv = lands ? map.uv[i] : glm::dvec2(0.0);
    switch (encoding) {
      case Encoding::Rg16:
        out.rg16[4 * i + 0] = encodeUnorm16(uv.x);
        out.rg16[4 * i + 1] = encodeUnorm16(uv.y);
        out.rg16[4 * i + 3] = lands ? 65535 : kHalf16;
        break;
      case Encoding::Exr:
        out.rgba32f[4 * i + 0] = float(uv.x);
        out.rgba32f[4 * i + 1] = float(uv.y);
        out.rgba32f[4 * i + 3] = lands ? 1.0f : 0.5f;
        break;
      case Encoding::Sky8: {
        Sky8 code = lands ? encodeSky8(uv) : Sky8{};
        out.sky8[4 * i + 0] = code.r;
        out.sky8[4 * i + 1] = code.g;
        out.sky8[4 * i + 2] = code.b;
        out.sky8[4 * i + 3] = lands ? 255 : kHalf8;
        break;
      }
    }
  }
  return out;
}

DecodedMap decodeMap(const MapPixels& pixels, Encoding encoding) {
  DecodedMap out;
  out.width = pixels.width;
  out.height = pixels.height;
  size_t n = size_t(pixels.width) * pixels.height;
  size_t have = encoding == Encoding::Rg16 ? pixels.rg16.size() : encoding == Encoding::Exr ? pixels.rgba32f.size()
                                                                                            : pixels.sky8.size();
  if (have != 4 * n) throw std::invalid_argument("decodeMap: the pixels do not fill the map");
  out.coverage.resize(n, Coverage::Empty);
  out.uv.resize(n, glm::dvec2(std::numeric_limits<double>::quiet_NaN()));
  // Alpha 1, 1/2 or 0, read with margin: above 3/4 lands, above 1/4 marked.
  auto coverageOf = [](double alpha) {
    return alpha > 0.75 ? Coverage::Lands : alpha > 0.25 ? Coverage::Marked : Coverage::Empty;
  };
  for (size_t i = 0; i < n; ++i) {
    switch (encoding) {
      case Encoding::Rg16:
        out.coverage[i] = coverageOf(decodeUnorm16(pixels.rg16[4 * i + 3]));
        if (out.coverage[i] == Coverage::Lands) {
          out.uv[i] = {decodeUnorm16(pixels.rg16[4 * i]), decodeUnorm16(pixels.rg16[4 * i + 1])};
        }
        break;
      case Encoding::Exr:
        out.coverage[i] = coverageOf(pixels.rgba32f[4 * i + 3]);
        if (out.coverage[i] == Coverage::Lands) out.uv[i] = {pixels.rgba32f[4 * i], pixels.rgba32f[4 * i + 1]};
        break;
      case Encoding::Sky8:
        out.coverage[i] = coverageOf(decodeUnorm8(pixels.sky8[4 * i + 3]));
        if (out.coverage[i] == Coverage::Lands) {
          out.uv[i] = decodeSky8({pixels.sky8[4 * i], pixels.sky8[4 * i + 1], pixels.sky8[4 * i + 2]});
        }
        break;
    }
  }
  return out;
}

std::vector<uint8_t> uvGradient(uint32_t size, bool tiled) {
  std::vector<uint8_t> rgba(size_t(size) * size * 4, 255);
  for (uint32_t y = 0; y < size; ++y) {
    for (uint32_t x = 0; x < size; ++x) {
      glm::dvec2 uv((x + 0.5) / size, (y + 0.5) / size);
      uint8_t* p = &rgba[(size_t(y) * size + x) * 4];
      if (tiled) {
        Sky8 code = encodeSky8(uv);
        p[0] = code.r, p[1] = code.g, p[2] = code.b;
      } else {
        p[0] = encodeUnorm8(uv.x), p[1] = encodeUnorm8(uv.y), p[2] = 0;
      }
    }
  }
  return rgba;
}

scene::Scene useGradient(const scene::Scene& source, uint32_t behindMaterial, uint32_t size, bool tiled) {
  if (behindMaterial >= source.materials.size() || !source.materials[behindMaterial].baseColorTexture.present()) {
    throw std::invalid_argument("useGradient: material " + std::to_string(behindMaterial) + " has no base colour texture");
  }
  scene::Scene s = source;
  scene::Texture gradient;
  gradient.name = tiled ? "uv gradient (sky8 tiles)" : "uv gradient";
  gradient.width = gradient.height = size;
  gradient.rgba = uvGradient(size, tiled);
  // Wrapped as the texture it stands in for, so it reads where that would.
  const scene::Texture& behind = source.textures.at(size_t(source.materials[behindMaterial].baseColorTexture.texture));
  gradient.repeatS = behind.repeatS, gradient.repeatT = behind.repeatT;
  gradient.mirrorS = behind.mirrorS, gradient.mirrorT = behind.mirrorT;
  gradient.linearFilter = false;                // a filtered gradient cracks
  s.textures.push_back(std::move(gradient));
  for (size_t i = 0; i < s.materials.size(); ++i) {
    scene::Material& m = s.materials[i];
    if (m.refractive()) {
      m.baseColorFactor = glm::vec4(1.0f);
      m.baseColorTexture = {};
      m.attenuationDistance = std::numeric_limits<float>::infinity();
      continue;
    }
    m.baseColorFactor = glm::vec4(0.0f, 0.0f, 0.0f, m.baseColorFactor.a);
    m.emissiveFactor = glm::vec3(0.0f);
    m.emissiveTexture = {};
    if (i == behindMaterial) {
      m.emissiveFactor = glm::vec3(1.0f);
      m.emissiveTexture = source.materials[i].baseColorTexture;
      m.emissiveTexture.texture = int(s.textures.size() - 1);
    }
  }
  // One dark light, so the headlight (what shades a scene without lights) adds no highlight.
  for (scene::Light& l : s.lights) l.intensity = 0.0f;
  if (s.lights.empty()) {
    scene::Light dark;
    dark.name = "dark";
    dark.type = scene::LightType::Directional;
    dark.intensity = 0.0f;
    s.lights.push_back(dark);
    scene::Node node;
    node.name = "dark light";
    node.light = 0;
    s.nodes.push_back(node);
    s.roots.push_back(int(s.nodes.size() - 1));
  }
  return s;
}

glm::dvec2 gradientUv(uint8_t r, uint8_t g, uint8_t b, bool tiled) {
  if (tiled) return decodeSky8({r, g, b});
  return {decodeUnorm8(r), decodeUnorm8(g)};
}

DecodedMap bakeThroughGradient(vk::Context& context, const scene::Scene& scene, const scene::Pose& pose,
                               const render::FrameSettings& settings, const RefractionBake& direct,
                               uint32_t gradientSize, bool tiled) {
  if (direct.behindMaterial == gpu::kNoHit) throw std::runtime_error("bake: no glass pixel lands on a textured surface");
  scene::Scene gradientScene = useGradient(scene, direct.behindMaterial, gradientSize, tiled);
  scene::Pose gradientPose = scene::evaluate(gradientScene, pose.time);
  render::Renderer renderer(context, gradientScene, gradientPose);
  render::FrameSettings plain = settings;
  plain.background = glm::vec3(0.0f);
  plain.optics.fresnel = false;
  render::RenderedFrame frame = render::renderFrame(renderer, gradientPose, plain);
  DecodedMap map;
  map.width = frame.width;
  map.height = frame.height;
  map.coverage.resize(frame.rgba.size());
  map.uv.resize(frame.rgba.size(), glm::dvec2(std::numeric_limits<double>::quiet_NaN()));
  // As an 8-bit sRGB image file would hold the render (IEC 61966-2-1, rounded).
  auto srgb8 = [](float linear) {
    double c = std::clamp(double(linear), 0.0, 1.0);
    double s = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
    return uint8_t(std::lround(s * 255.0));
  };
  for (size_t i = 0; i < frame.rgba.size(); ++i) {
    map.coverage[i] = direct.coverage(i);
    if (map.coverage[i] != Coverage::Lands) continue;
    const glm::vec4& c = frame.rgba[i];
    map.uv[i] = gradientUv(srgb8(c.r), srgb8(c.g), srgb8(c.b), tiled);
  }
  return map;
}

}  // namespace snell::bake
