// The raster pass: the viewport's own drawing of the scene, from the deformed
// buffers the trace uses, with each transmissive fragment taking the trace
// image's texel at its pixel (the talk's viewport shader). Two halves: a
// depth pre-pass (which also marks where the visible face is transmissive,
// for the masked trace), then the shading pass, one fragment per pixel. The
// trace image reaches it through pipeline barriers, never through host memory.
#pragma once

#include "render/frame_settings.h"
#include "render/refraction_map.h"
#include "render/scene_gpu.h"
#include "scene/scene.h"
#include "scene/view.h"
#include "shared/raster.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/graphics_program.h"

#include <glm/glm.hpp>

#include <memory>
#include <optional>
#include <span>

namespace snell::render {

/// Formats of the raster pass's attachments.
inline constexpr VkFormat kCompositeFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
inline constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
inline constexpr VkFormat kMaskFormat = VK_FORMAT_R32_UINT;

/// How transmissive fragments find what they show, when nothing is traced.
/// Each value is the raster shader's flag for it (shared/raster.h), so a new
/// approximation is a flag, its shading and a value here.
enum class ScreenSpace : uint32_t {
  Off = 0,  ///< the trace image at the fragment's own pixel
  /// The picture behind the glass, displaced by the shading normal (GPU Gems 2, ch. 19).
  NormalOffset = gpu::kRasterFlagNormalOffset,
  /// The picture behind the glass where the refracted ray meets the plane through it.
  IrisPlane = gpu::kRasterFlagIrisPlane,
  /// A baked refraction map (RasterOptions::refractionMap), the texture behind read where it says.
  RefractionMap = gpu::kRasterFlagRefractionMap,
};

/// Perspective: the near and far planes' distances. Orthographic: the depth
/// range along the view's forward axis.
struct DepthRange {
  double nearPlane = 1e-3, farPlane = 1e3;
  friend bool operator==(const DepthRange&, const DepthRange&) = default;
};

struct RasterOptions {
  /// Off: transmissive faces are left out, so glass is seen straight through
  /// (as IOR 1 would show it) and nothing is traced.
  bool refraction = true;
  /// With refraction: a screen-space approximation instead of the trace.
  ScreenSpace screenSpace = ScreenSpace::Off;
  /// RefractionMap's map: unset, the one Renderer::bakeRefractionMap keeps
  /// for the view. A map of the caller's own stays theirs while frames that read it
  /// are in flight; new content in the same object is invisible to the
  /// renderer: call Renderer::invalidateViews() after.
  const RefractionMapBuffer* refractionMap = nullptr;
  /// NormalOffset's displacement per unit of normal, in image heights.
  float offsetStrength = 0.02f;
  /// Draws every triangle's edges over the shaded image.
  bool wireframe = false;
  glm::vec4 wireColor{0.95f, 0.8f, 0.3f, 0.35f};  ///< blended over the image by its alpha
  /// The depth range drawn; unset, the Renderer fits it each frame to its
  /// items' bounding spheres at the frame's pose (fitDepthRange()).
  std::optional<DepthRange> depth;
  friend bool operator==(const RasterOptions&, const RasterOptions&) = default;
};

/// Near and far planes that hold everything within [lo, hi] seen from `view`;
/// the default range where the box is empty.
DepthRange fitDepthRange(const scene::View& view, const glm::dvec3& lo, const glm::dvec3& hi);

/// What the raster pass draws: the scene's buffers and the frame's instances and lights.
struct RasterScene {
  const SceneGpu* scene = nullptr;
  const scene::Scene* model = nullptr;
  const vk::Buffer* instances = nullptr;
  const vk::Buffer* lights = nullptr;
  uint32_t lightCount = 0;
  glm::dvec3 origin{0.0};  ///< the frame origin the instances are relative to
};

class RasterPass {
 public:
  explicit RasterPass(vk::Context& context);
  ~RasterPass();

  /// Its pipelines on `context`'s device: the depth pre-pass, the pre-pass
  /// with the transmissive mask, the shading pass and, where the device draws
  /// lines, the wireframe.
  static std::vector<vk::GraphicsProgramDesc> programDescs(const vk::Context& context);

  /// The depth pre-pass into `depth` (kDepthFormat, GENERAL, cleared). With
  /// `mask` (kMaskFormat, GENERAL) it also writes 1 where the nearest face
  /// is transmissive and 0 elsewhere; without, `colorTarget` (kCompositeFormat)
  /// stands in as the attachment it leaves untouched.
  void recordDepth(vk::Commands& commands, const RasterScene& scene, const FrameSettings& settings,
                   const RasterOptions& options, const vk::Image& depth, const vk::Image* mask,
                   const vk::Image& colorTarget) const;
  /// The shading pass into `target` (kCompositeFormat, GENERAL, cleared to the
  /// background) over the pre-pass's depth; transmissive fragments take
  /// `traceImage`'s texel (rgba16f, GENERAL, written before a compute-to-graphics
  /// barrier), or with a screen-space method a displaced texel of the picture
  /// recordBehind() drew there; `behindDepth` is that picture's depth.
  /// `traced`: the trace drew this frame's see-through pixels into
  /// `traceImage`, so faces alpha may make see-through take it too (else
  /// they are shaded opaque).
  void recordShading(vk::Commands& commands, const RasterScene& scene, const FrameSettings& settings,
                     const RasterOptions& options, const vk::Image& traceImage, const vk::Image& target,
                     const vk::Image& depth, const vk::Image& behindDepth, bool traced) const;
  /// For the screen-space methods: the picture behind the glass (every
  /// opaque face, glass left out) into `behind` (rgba16f, colour attachment
  /// and storage) and its view depth into `behindDepth` (kMaskFormat), using
  /// `depth` as scratch; visible to the shading pass's fragment shaders after.
  void recordBehind(vk::Commands& commands, const RasterScene& scene, const FrameSettings& settings,
                    const RasterOptions& options, const vk::Image& depth, const vk::Image& behindDepth,
                    const vk::Image& behind) const;

 private:
  gpu::RasterPush push(const RasterScene& scene, const FrameSettings& settings, const RasterOptions& options) const;
  void recordDepthPass(vk::Commands& commands, const RasterScene& scene, const FrameSettings& settings,
                       const RasterOptions& options, const vk::Image& depth, const vk::Image* mask,
                       const vk::Image& colorTarget, uint32_t extraFlags, const char* passName) const;
  void recordShadingPass(vk::Commands& commands, const RasterScene& scene, const FrameSettings& settings,
                         const RasterOptions& options, const vk::Image& traceImage, const vk::Image& target,
                         const vk::Image& depth, const vk::Image& behindDepth, uint32_t extraFlags,
                         const char* passName) const;
  void drawItems(vk::Commands& commands, const vk::GraphicsProgram& program, const RasterScene& scene,
                 const RasterOptions& options, const gpu::RasterPush& push, std::span<const vk::BufferBinding> resources,
                 VkRect2D area) const;

  vk::Context& context_;
  std::unique_ptr<vk::GraphicsProgram> depth_, mask_, fill_, wire_;
  vk::Buffer noMap_;  ///< bound as the refraction map when a view has none
};

}  // namespace snell::render
