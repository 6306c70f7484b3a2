// A texture's mip chain as shaders/shared/scene.h lays it out and
// shaders/comp/texture_mips.comp makes it on the GPU; here in double, for the
// reference tracer and the tests that hold the GPU to it.
#pragma once

#include "scene/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace snell::scene {

/// Mip levels of a width x height texture: down to 1x1, each level half the
/// one above (rounded down, at least 1).
uint32_t mipLevels(uint32_t width, uint32_t height);
/// Texels of a width x height texture's whole mip chain.
uint64_t mipChainTexels(uint32_t width, uint32_t height);

/// Per texture: true where it holds colour (sRGB, averaged in linear light),
/// false where only data slots (the IOR texture, the normal map) read it
/// (averaged as bytes).
std::vector<bool> colourTextures(const Scene& scene);

/// 0.5 log2(W H |det|): how many texels of level 0 one unit of UV area
/// covers through the reference's transform (its 2x2 part), in the log2 terms
/// of the texture level of detail (shaders/shared/trace.h: Textures).
double textureLodOffset(const Texture& texture, const TextureRef& ref);

/// Per texture: true where a material reads it (base colour, emissive or
/// IOR). Only those go to the GPU; normal, occlusion and metallic-roughness
/// maps, which snell does not draw, stay on the host.
std::vector<bool> drawnTextures(const Scene& scene);

/// One RGBA8 level of a mip chain.
struct MipLevel {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;
};

/// The level below `above`: each texel the mean of the 2x2 block it covers
/// (clamped at odd edges), RGB in linear light for colour textures (sRGB
/// decoded, averaged, encoded, rounded to a byte), alpha and data as bytes.
MipLevel nextMipLevel(const MipLevel& above, bool colour);

/// Every level of `texture`, level 0 its own bytes. Empty for an unusable texture.
std::vector<MipLevel> mipChain(const Texture& texture, bool colour);

/// GPU bytes of every drawn texture's whole mip chain (RGBA8).
uint64_t textureChainBytes(const Scene& scene);

/// Fits the scene's drawn textures, mips included, within `budgetBytes`:
/// while they take more, the largest is replaced by its next mip level.
/// Returns one note per texture made smaller, naming its sizes and the budget.
/// Throws SceneError naming the numbers when even 1x1 textures do not fit.
std::vector<std::string> fitTextureBudget(Scene& scene, uint64_t budgetBytes);

}  // namespace snell::scene
