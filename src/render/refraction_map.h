// The refraction-map method's map (issue 16): a trace of every pixel at one
// pose and view, with its AOVs, says per pixel whether the visible face is
// glass, where the refracted path landed and on which texture, and how the
// traced colour splits into what the texture's colour is multiplied by
// (weight) and what is added whatever it holds (shine). Nothing is filtered
// or anti-aliased: a filtered map cracks.
//
// The Renderer bakes the map and keeps it on the GPU for the raster pass
// (Renderer::bakeRefractionMap); bake/ writes it to files and reads the DCC
// route's, in refraction_map.h's encodings there.
#pragma once

#include "scene/scene.h"
#include "shared/raster.h"
#include "shared/trace.h"
#include "vk/buffer.h"
#include "vk/context.h"

#include <cstdint>
#include <vector>

namespace snell::render {

/// What a baked pixel holds, as a map file's alpha says it.
enum class Coverage : uint8_t {
  Empty,   ///< the visible face is not glass (alpha 0)
  Marked,  ///< glass, but the path lands on no texel of the texture behind (alpha 1/2): not guessed
  Lands,   ///< glass, and the UV where its path lands on the texture behind (alpha 1)
};

struct RefractionBake {
  uint32_t width = 0, height = 0;
  /// Per pixel, row 0 at the top, as the raster pass reads them.
  std::vector<gpu::RefractionTexel> texels;
  /// The texture behind: the material whose base colour texture most paths
  /// land on (gpu::kNoHit: none did). A map file's UVs are in its texture.
  uint32_t behindMaterial = gpu::kNoHit;

  /// Lands only where the path lands on `behindMaterial`'s texture.
  Coverage coverage(size_t pixel) const;
  size_t count(Coverage c) const;
};

/// The bake of a trace's AOVs (width * height, row 0 at the top).
RefractionBake bakeFromAov(uint32_t width, uint32_t height, const std::vector<gpu::TraceAov>& aov,
                           const scene::Scene& scene);

/// A baked refraction map on the GPU, as the raster pass reads it: one
/// gpu::RefractionTexel per baked pixel, row 0 at the top.
struct RefractionMapBuffer {
  vk::Buffer texels;
  uint32_t width = 0, height = 0;
};

/// The bake on the GPU (waits for the upload).
RefractionMapBuffer uploadRefractionMap(vk::Context& context, const RefractionBake& bake);

}  // namespace snell::render
