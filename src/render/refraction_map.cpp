#include "render/refraction_map.h"

#include "vk/commands.h"

#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

namespace snell::render {

namespace {

bool landsOnTexture(const gpu::RefractionTexel& t) {
  return t.material != gpu::kNoHit && std::isfinite(t.u) && std::isfinite(t.v);
}

}  // namespace

Coverage RefractionBake::coverage(size_t pixel) const {
  const gpu::RefractionTexel& t = texels[pixel];
  if (t.shine.w == 0.0f) return Coverage::Empty;
  return landsOnTexture(t) && t.material == behindMaterial ? Coverage::Lands : Coverage::Marked;
}

size_t RefractionBake::count(Coverage c) const {
  size_t n = 0;
  for (size_t i = 0; i < texels.size(); ++i) n += coverage(i) == c;
  return n;
}

RefractionBake bakeFromAov(uint32_t width, uint32_t height, const std::vector<gpu::TraceAov>& aov,
                           const scene::Scene& scene) {
  if (aov.size() != size_t(width) * height) throw std::invalid_argument("bake: the AOVs do not fill the image");
  RefractionBake bake;
  bake.width = width;
  bake.height = height;
  bake.texels.resize(aov.size());
  std::map<uint32_t, size_t> landings;
  for (size_t i = 0; i < aov.size(); ++i) {
    const gpu::TraceAov& a = aov[i];
    gpu::RefractionTexel& t = bake.texels[i];
    t.material = gpu::kNoHit;
    t.u = t.v = std::numeric_limits<float>::quiet_NaN();
    // The visible face is glass where the primary ray crossed an interface first.
    if (a.interfaces == 0) continue;
    t.shine = glm::vec4(a.shineR, a.shineG, a.shineB, 1.0f);
    t.weight = glm::vec4(a.weightR, a.weightG, a.weightB, a.landingLod);
    t.material = a.landingMaterial;
    t.u = a.landingU;
    t.v = a.landingV;
    if (t.material != gpu::kNoHit && t.material >= scene.materials.size()) {
      throw std::runtime_error("bake: pixel " + std::to_string(i) + " landed on material " + std::to_string(t.material) +
                               " of " + std::to_string(scene.materials.size()));
    }
    if (landsOnTexture(t)) ++landings[t.material];
  }
  size_t most = 0;
  for (const auto& [material, n] : landings) {
    if (n > most) most = n, bake.behindMaterial = material;
  }
  return bake;
}

RefractionMapBuffer uploadRefractionMap(vk::Context& context, const RefractionBake& bake) {
  RefractionMapBuffer map;
  map.width = bake.width;
  map.height = bake.height;
  VkDeviceSize bytes = bake.texels.size() * sizeof(gpu::RefractionTexel);
  map.texels = vk::Buffer(context, {bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                    vk::MemoryDomain::Device, "refraction map"});
  vk::upload(context, map.texels, bake.texels.data(), bytes);
  return map;
}

}  // namespace snell::render
