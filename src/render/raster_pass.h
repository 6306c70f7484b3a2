// The raster pass: the viewport's own drawing of the scene, from the deformed
// buffers the trace used, with each transmissive fragment taking the trace
// image's texel at its pixel (the talk's viewport shader). The trace image
// reaches it through one pipeline barrier, never through host memory.
#pragma once

#include "render/renderer.h"
#include "scene/view.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/graphics_program.h"

#include <glm/glm.hpp>

#include <memory>

namespace snell::render {

/// Formats of the raster pass's attachments.
inline constexpr VkFormat kCompositeFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
inline constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

struct RasterOptions {
  /// Off: transmissive faces are left out, so glass is seen straight through
  /// (as IOR 1 would show it) and the trace image is not read.
  bool refraction = true;
  /// Draws every triangle's edges over the shaded image.
  bool wireframe = false;
  glm::vec4 wireColor{0.95f, 0.8f, 0.3f, 0.35f};  ///< blended over the image by its alpha
  /// Perspective: the near plane's distance. Orthographic: the depth range
  /// along the view's forward axis. depthRange() picks them from the scene.
  double nearPlane = 1e-3, farPlane = 1e3;
};

/// Near and far planes that hold everything within [lo, hi] seen from `view`
/// (nearPlane/farPlane of RasterOptions).
void fitDepthRange(const scene::View& view, const glm::dvec3& lo, const glm::dvec3& hi, RasterOptions& options);

class RasterPass {
 public:
  explicit RasterPass(vk::Context& context);
  ~RasterPass();

  /// Records the view of the pose `renderer` last updated into `target`
  /// (kCompositeFormat, GENERAL) with `depth` (kDepthFormat, GENERAL); both and
  /// `traceImage` (GENERAL, written by Renderer::trace for this view) have the
  /// frame's size. Starts with the compute-to-graphics barrier.
  void record(vk::Commands& commands, const Renderer& renderer, const FrameSettings& settings,
              const vk::Image& traceImage, const vk::Image& target, const vk::Image& depth,
              const RasterOptions& options = {}) const;

 private:
  vk::Context& context_;
  std::unique_ptr<vk::GraphicsProgram> depth_, fill_, wire_;
};

/// A traced frame and its raster composite, read back (tests, `snell render --viewport`).
struct CompositeFrame {
  RenderedFrame trace;            ///< the trace image and its AOV
  std::vector<glm::vec4> rgba;    ///< the composite, row 0 at the top
};

/// Renders one frame (update, trace, raster) and reads both images back.
CompositeFrame renderComposite(vk::Context& context, Renderer& renderer, const scene::Pose& pose,
                               const FrameSettings& settings, const RasterOptions& options, bool withAov = false);

}  // namespace snell::render
