// One view rendered and read back, waiting for the GPU: what the golden
// tests, one-shot commands and benchmarks ask of the Renderer most often.
#pragma once

#include "render/raster_pass.h"
#include "render/refraction_map.h"
#include "render/renderer.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace snell::render {

/// A frame brought back to the host: linear RGBA, row 0 at the top.
struct RenderedFrame {
  uint32_t width = 0, height = 0;
  std::vector<glm::vec4> rgba;
  std::vector<gpu::TraceAov> aov;  ///< empty unless asked for
  /// Triangles left out of this frame's tree because deformation made a vertex
  /// NaN or infinite (all triangles are checked on a build, deforming ones on a refit).
  uint32_t droppedTriangles = 0;
  std::vector<vk::PassTime> passes;
  FrameStats stats;
};

/// Renders one view's trace of every pixel and reads it back.
RenderedFrame renderFrame(Renderer& renderer, const scene::Pose& pose, const FrameSettings& settings,
                          bool withAov = false);

/// A traced frame and its raster composite, read back (tests, `snell render --viewport`).
struct CompositeFrame {
  RenderedFrame trace;          ///< the trace image (whole unless masked) and its AOV
  std::vector<glm::vec4> rgba;  ///< the composite, row 0 at the top
};

/// Renders one viewport composite (update, trace, raster) and reads both images back.
CompositeFrame renderComposite(Renderer& renderer, const scene::Pose& pose, const FrameSettings& settings,
                               const RasterOptions& options, bool withAov = false, bool masked = false);

/// The refraction-map method's map of `settings` at `pose`, traced and baked
/// on the host only, for a map file; Renderer::bakeRefractionMap also keeps
/// it on the GPU for the raster pass.
RefractionBake bakeRefraction(Renderer& renderer, const scene::Pose& pose, const FrameSettings& settings);

}  // namespace snell::render
