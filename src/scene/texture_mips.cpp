#include "scene/texture_mips.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace snell::scene {

uint32_t mipLevels(uint32_t width, uint32_t height) {
  uint32_t levels = 1;
  for (uint32_t size = std::max(width, height); size > 1; size >>= 1) ++levels;
  return levels;
}

uint64_t mipChainTexels(uint32_t width, uint32_t height) {
  uint64_t texels = 0;
  for (uint32_t level = 0; level < mipLevels(width, height); ++level) {
    texels += uint64_t(std::max(width >> level, 1u)) * std::max(height >> level, 1u);
  }
  return texels;
}

std::vector<bool> drawnTextures(const Scene& scene) {
  std::vector<bool> drawn(scene.textures.size(), false);
  for (const Material& m : scene.materials) {
    for (const TextureRef* ref : {&m.baseColorTexture, &m.emissiveTexture, &m.normalTexture, &m.iorTexture}) {
      if (ref->present() && size_t(ref->texture) < drawn.size()) drawn[size_t(ref->texture)] = true;
    }
  }
  return drawn;
}

std::vector<bool> colourTextures(const Scene& scene) {
  std::vector<bool> data(scene.textures.size(), false), colour(scene.textures.size(), false);
  auto mark = [&](const TextureRef& ref, std::vector<bool>& as) {
    if (ref.present() && size_t(ref.texture) < scene.textures.size()) as[size_t(ref.texture)] = true;
  };
  for (const Material& m : scene.materials) {
    mark(m.baseColorTexture, colour);
    mark(m.emissiveTexture, colour);
    mark(m.iorTexture, data);
    mark(m.normalTexture, data);
  }
  for (size_t t = 0; t < colour.size(); ++t) colour[t] = colour[t] || !data[t];
  return colour;
}

double textureLodOffset(const Texture& texture, const TextureRef& ref) {
  const glm::mat3& t = ref.transform;  // column-major: t[column][row]
  double det = double(t[0][0]) * double(t[1][1]) - double(t[1][0]) * double(t[0][1]);
  return 0.5 * std::log2(double(texture.width) * double(texture.height) * std::abs(det));
}

namespace {

uint8_t encodeSrgb(double linear) {
  double s = linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
  return uint8_t(std::lround(std::clamp(s, 0.0, 1.0) * 255.0));
}

}  // namespace

MipLevel nextMipLevel(const MipLevel& above, bool colour) {
  double decode[256];
  for (int v = 0; v < 256; ++v) decode[v] = srgbToLinear(uint8_t(v));
  MipLevel below;
  below.width = std::max(above.width / 2, 1u);
  below.height = std::max(above.height / 2, 1u);
  below.rgba.resize(size_t(below.width) * below.height * 4);
  for (uint32_t y = 0; y < below.height; ++y) {
    for (uint32_t x = 0; x < below.width; ++x) {
      for (int c = 0; c < 4; ++c) {
        double linearSum = 0.0;
        uint32_t byteSum = 0;
        for (uint32_t j = 0; j < 2; ++j) {
          for (uint32_t i = 0; i < 2; ++i) {
            uint32_t sx = std::min(2 * x + i, above.width - 1), sy = std::min(2 * y + j, above.height - 1);
            uint8_t v = above.rgba[(size_t(sy) * above.width + sx) * 4 + size_t(c)];
            linearSum += decode[v];
            byteSum += v;
          }
        }
        // Data bytes averaged in integers, half up, as texture_mips.comp does (its comment says why).
        below.rgba[(size_t(y) * below.width + x) * 4 + size_t(c)] =
            colour && c < 3 ? encodeSrgb(linearSum / 4.0) : uint8_t((byteSum + 2) / 4);
      }
    }
  }
  return below;
}

std::vector<MipLevel> mipChain(const Texture& texture, bool colour) {
  std::vector<MipLevel> chain;
  if (texture.width == 0 || texture.height == 0 || texture.rgba.size() < size_t(texture.width) * texture.height * 4) {
    return chain;
  }
  chain.push_back({texture.width, texture.height, texture.rgba});
  chain.front().rgba.resize(size_t(texture.width) * texture.height * 4);
  for (uint32_t level = 1; level < mipLevels(texture.width, texture.height); ++level) {
    chain.push_back(nextMipLevel(chain.back(), colour));
  }
  return chain;
}

uint64_t textureChainBytes(const Scene& scene) {
  const std::vector<bool> drawn = drawnTextures(scene);
  uint64_t bytes = 0;
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    const Texture& t = scene.textures[i];
    if (drawn[i] && t.width && t.height) bytes += mipChainTexels(t.width, t.height) * 4;
  }
  return bytes;
}

std::vector<std::string> fitTextureBudget(Scene& scene, uint64_t budgetBytes) {
  const uint64_t before = textureChainBytes(scene);
  if (before <= budgetBytes) return {};
  const std::vector<bool> colour = colourTextures(scene), drawn = drawnTextures(scene);
  std::map<size_t, std::pair<uint32_t, uint32_t>> original;  // texture: its size as loaded
  uint64_t bytes = before;
  while (bytes > budgetBytes) {
    size_t largest = scene.textures.size();
    uint64_t most = 1;  // 1x1 textures cannot shrink
    for (size_t i = 0; i < scene.textures.size(); ++i) {
      const Texture& t = scene.textures[i];
      uint64_t texels = uint64_t(t.width) * t.height;
      if (drawn[i] && texels > most && t.rgba.size() >= texels * 4) most = texels, largest = i;
    }
    if (largest == scene.textures.size()) {
      throw SceneError(scene.source + ": textures need " + mebibytes(bytes) + " with their mips even at 1x1; the texture budget is " +
                       mebibytes(budgetBytes));
    }
    Texture& t = scene.textures[largest];
    original.emplace(largest, std::make_pair(t.width, t.height));
    const uint64_t was = mipChainTexels(t.width, t.height) * 4;
    MipLevel next = nextMipLevel({t.width, t.height, std::move(t.rgba)}, colour[largest]);
    t.width = next.width;
    t.height = next.height;
    t.rgba = std::move(next.rgba);
    bytes = bytes - was + mipChainTexels(t.width, t.height) * 4;
  }
  std::vector<std::string> notes;
  for (const auto& [index, size] : original) {
    const Texture& t = scene.textures[index];
    notes.push_back("texture " + std::to_string(index) + (t.name.empty() ? "" : " '" + t.name + "'") + " loaded at " +
                    std::to_string(t.width) + "x" + std::to_string(t.height) + " instead of " +
                    std::to_string(size.first) + "x" + std::to_string(size.second) + ": textures take " +
                    mebibytes(before) + " with mips, over the texture budget of " + mebibytes(budgetBytes) +
                    " (now " + mebibytes(bytes) + ")");
  }
  return notes;
}

}  // namespace snell::scene
