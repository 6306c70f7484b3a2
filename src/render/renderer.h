// One frame of snell: deform -> bottom-level BVH (build once, then refit what
// deformed) -> top level -> trace, each a timed pass on one command buffer.
// Nothing comes back to the host unless renderFrame is asked for pixels.
#pragma once

#include "render/bvh.h"
#include "render/deform_pass.h"
#include "render/scene_gpu.h"
#include "scene/evaluate.h"
#include "scene/scene.h"
#include "scene/view.h"
#include "shared/trace.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/compute_program.h"
#include "vk/context.h"
#include "vk/upload_arena.h"

#include <glm/glm.hpp>

#include <memory>
#include <vector>

namespace snell::render {

struct FrameSettings {
  uint32_t width = 0, height = 0;
  scene::View view;
  glm::vec3 background{0.02f, 0.02f, 0.025f};
  uint32_t maxInterfaces = gpu::kDefaultMaxInterfaces;
  /// When not empty: width * height primary rays in world space, pixel i
  /// (row-major) tracing rays[i] instead of the camera's ray through it.
  /// The view's eye still sets the camera-relative origin the trace works in.
  std::vector<scene::Ray> rays;
};

class Renderer {
 public:
  /// Uploads the scene and builds the passes for the items of `layout`.
  Renderer(vk::Context& context, const scene::Scene& scene, const scene::Pose& layout);
  ~Renderer();

  /// Records a frame of `pose` seen from settings.view into `target` (rgba16f,
  /// GENERAL layout) and, when `aov` is given, per-pixel gpu::TraceAov records.
  /// `rays`, when given, holds width * height gpu::GpuRay (camera-relative) to
  /// trace instead of the camera's. update() at the view's eye, then trace().
  void record(vk::Commands& commands, const scene::Pose& pose, const FrameSettings& settings, const vk::Image& target,
              const vk::Buffer* aov = nullptr, const vk::Buffer* rays = nullptr);

  /// Records the passes that depend on the pose but not on a view: deform,
  /// bottom level, top level, with the scene rebased to `origin` (world space,
  /// in double) so float precision does not depend on where the scene is. The
  /// host writes the frame's instances and lights: the previous frame must
  /// have finished.
  void update(vk::Commands& commands, const scene::Pose& pose, const glm::dvec3& origin);
  /// Records the trace pass of one view of the pose last updated; a frame may
  /// trace several views (viewports) whose eyes are near its origin.
  void trace(vk::Commands& commands, const FrameSettings& settings, const vk::Image& target,
             const vk::Buffer* aov = nullptr, const vk::Buffer* rays = nullptr);

  /// Forces the next frame to rebuild the bottom level instead of refitting it.
  void invalidateBlas() { blasBuilt_ = false; }

  const SceneGpu& sceneGpu() const { return scene_; }
  const scene::Scene& scene() const { return sceneModel_; }
  /// The last update's instances (gpu::GpuInstance, rebased to its origin) and
  /// lights (gpu::GpuLight), which the raster pass shares.
  const vk::Buffer& instances() const { return instances_; }
  const vk::Buffer& lights() const { return lights_; }
  uint32_t lightCount() const { return lightCount_; }
  const glm::dvec3& origin() const { return origin_; }
  const Bvh& blas() const { return blas_; }
  const Bvh& tlas() const { return tlas_; }
  BvhBuilder& builder() { return builder_; }
  /// GPU memory of geometry, BVHs and per-frame buffers (not the output image).
  uint64_t memoryBytes() const;

 private:
  vk::Context& context_;
  const scene::Scene& sceneModel_;
  SceneGpu scene_;
  std::unique_ptr<DeformPass> deform_;
  BvhBuilder builder_;
  Bvh blas_, tlas_;
  bool blasBuilt_ = false;
  bool updated_ = false;
  glm::dvec3 origin_{0.0};
  uint32_t lightCount_ = 0;
  vk::Buffer instances_, lights_, placeholder_;
  vk::UploadArena arena_;
  std::unique_ptr<vk::ComputeProgram> trace_;
};

/// A frame brought back to the host: linear RGBA, row 0 at the top.
struct RenderedFrame {
  uint32_t width = 0, height = 0;
  std::vector<glm::vec4> rgba;
  std::vector<gpu::TraceAov> aov;  ///< empty unless asked for
  /// Triangles left out of this frame's tree because deformation made a vertex
  /// NaN or infinite (all triangles are checked on a build, deforming ones on a refit).
  uint32_t droppedTriangles = 0;
  std::vector<vk::PassTime> passes;
};

/// What one frame writes, sized for its settings: the trace image (rgba16f),
/// the AOV buffer when asked for, the ray list when the settings give one.
struct FrameTargets {
  vk::Image image;
  vk::Buffer aov, rays;
};
FrameTargets makeFrameTargets(vk::Context& context, const FrameSettings& settings, bool withAov);
/// Reads a completed frame's targets back, with the passes `commands` timed.
RenderedFrame readFrame(vk::Context& context, const Renderer& renderer, const FrameTargets& targets,
                        const vk::Commands& commands);
/// A whole rgba16f image (GENERAL layout) as linear floats, row 0 at the top.
std::vector<glm::vec4> downloadRgba16f(vk::Context& context, const vk::Image& image);

/// Renders one frame and reads it back (waits for the GPU).
RenderedFrame renderFrame(vk::Context& context, Renderer& renderer, const scene::Pose& pose,
                          const FrameSettings& settings, bool withAov = false);

/// Checks a requested image size against the device: throws
/// std::invalid_argument saying what is wrong.
void checkImageSize(const vk::Context& context, uint32_t width, uint32_t height);

}  // namespace snell::render
