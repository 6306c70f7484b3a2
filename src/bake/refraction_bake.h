// Refraction maps as files: the renderer bakes the map
// (render/refraction_map.h, Renderer::bakeRefractionMap); a file holds only
// its UVs and their coverage, in one of refraction_map.h's encodings, and the
// DCC route bakes one through a UV gradient instead.
#pragma once

#include "bake/refraction_map.h"
#include "render/refraction_map.h"
#include "render/raster_pass.h"
#include "render/one_view.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/scene.h"
#include "shared/raster.h"
#include "shared/trace.h"
#include "vk/context.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace snell::bake {

// The bake is the renderer's; this layer names it as its own.
using render::Coverage;
using render::RefractionBake;

/// One line for a user: "N glass pixels; L land on 'iris' (its texture 'x',
/// WxH), M marked (no texel of it behind)".
std::string describe(const RefractionBake& bake, const scene::Scene& scene);

/// A pixel's UV as map files store it: wrapped into [0, 1] the way the
/// texture behind's sampler wraps it (repeat, mirrored repeat or clamp).
glm::dvec2 storedUv(const RefractionBake& bake, size_t pixel, const scene::Scene& scene);

enum class Encoding { Rg16, Exr, Sky8 };
std::optional<Encoding> encodingFromName(std::string_view name);
const char* encodingName(Encoding encoding);

/// A map file's pixels, RGBA, row 0 at the top: RG the UV (rg16: value /
/// 65535; exr: the UV; sky8: RGB the sky8 code), A the coverage (1, 1/2, 0
/// of the format's range). Marked and empty pixels hold 0 in RGB.
struct MapPixels {
  uint32_t width = 0, height = 0;
  std::vector<uint16_t> rg16;  ///< Encoding::Rg16
  std::vector<float> rgba32f;  ///< Encoding::Exr
  std::vector<uint8_t> sky8;   ///< Encoding::Sky8
};

/// A map as files hold it, decoded: per pixel its coverage and, where it
/// lands, the UV (wrapped into [0, 1]; NaN elsewhere).
struct DecodedMap {
  uint32_t width = 0, height = 0;
  std::vector<Coverage> coverage;
  std::vector<glm::dvec2> uv;
};
/// The bake as a file would hold it, before encoding.
DecodedMap storedMap(const RefractionBake& bake, const scene::Scene& scene);
MapPixels encodeMap(const DecodedMap& map, Encoding encoding);
/// A map file's pixels decoded with the exact inverse of the encoding.
DecodedMap decodeMap(const MapPixels& pixels, Encoding encoding);

/// The DCC route's texture: a UV gradient, red = u and green = v (plain,
/// 8-bit), or tiled 16 x 16 with blue the tile (sky8's codes), `size` texels
/// on a side, each texel holding the code of its centre. Placed on the
/// surface behind the glass as its only light (useGradient), rendered without
/// filtering, and read back, it gives the map a DCC bake would.
std::vector<uint8_t> uvGradient(uint32_t size, bool tiled);

/// A copy of `scene` set up as a DCC bake renders the gradient: the texture
/// behind is replaced by `gradient` (nearest filtering, clamped), emitted as
/// the material's only colour; every other material is black; glass is
/// clear (white, no volume); no light adds anything. With Fresnel and
/// texture level of detail off in the frame, a pixel's colour is the
/// gradient's texel where its path lands.
scene::Scene useGradient(const scene::Scene& scene, uint32_t behindMaterial, uint32_t size, bool tiled);

/// The UV that a gradient colour (8-bit sRGB as an image file holds it) stands for.
glm::dvec2 gradientUv(uint8_t r, uint8_t g, uint8_t b, bool tiled);

/// The DCC route: `direct`'s pose and view rendered by the trace with the
/// gradient on the texture behind (useGradient; Fresnel off, background
/// black), its colours read back as 8-bit sRGB and decoded. Coverage is
/// `direct`'s (a DCC's alpha); the UV comes from the colours alone.
DecodedMap bakeThroughGradient(vk::Context& context, const scene::Scene& scene, const scene::Pose& pose,
                               const render::FrameSettings& settings, const RefractionBake& direct,
                               uint32_t gradientSize, bool tiled);

}  // namespace snell::bake
