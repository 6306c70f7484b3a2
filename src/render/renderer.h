// The frame: one object runs a frame's passes in order with the barriers
// between them, keeps frames in flight, and owns what changed and what is
// skipped. Callers (the CLI, the viewer, benchmarks, a host application)
// describe what they want of a frame (a pose and some views) and never order
// passes themselves.
//
// A frame: deform (only the items whose pose changed) -> bottom-level trees
// (built once, then refitted where positions changed, rebuilt where the
// surface area heuristic says refitting has spoiled them) -> top level (only
// when an instance moved) -> per view, either the trace of every pixel, or
// the viewport composite: the raster pass's depth pre-pass, the trace of just
// the pixels whose visible face is transmissive, and the raster pass's
// shading -> what the caller asked to read back, in the frame's own submit.
// Positions in the trees are relative to a frame origin near the cameras,
// moved only when a camera gets far from it (so orbiting alone touches no tree).
#pragma once

#include "render/bvh.h"
#include "render/deform_pass.h"
#include "render/frame_settings.h"
#include "render/raster_pass.h"
#include "render/scene_gpu.h"
#include "render/scene_state.h"
#include "render/trace_pass.h"
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

#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <vector>

namespace snell::render {

enum class ViewOutput {
  Trace,      ///< every pixel traced (the CLI's default image, the golden tests)
  Composite,  ///< the viewport: raster pass, transmissive pixels traced
};

/// What a view brings back to the host with its frame. It never changes
/// what the view draws, so it takes no part in comparing requests.
struct ReadbackRequest {
  bool enabled = false;  ///< bring the images (and AOV) back with the frame
  /// Keep the images as the GPU's half floats (ViewPixels::*Half), for
  /// writers that convert them once, straight to the file's encoding.
  bool half = false;
  /// A composite's trace image too (off: the composite alone).
  bool trace = true;
  friend bool operator==(const ReadbackRequest&, const ReadbackRequest&) { return true; }
};

/// One view of a frame.
struct ViewRequest {
  FrameSettings settings;
  ViewOutput output = ViewOutput::Trace;
  RasterOptions raster;  ///< composite only
  /// Composite only: trace just the pixels whose visible face is transmissive
  /// (off: trace every pixel, so the trace image is whole, for tests).
  bool masked = true;
  /// Trace output only: the closest hits come from the driver's own ray
  /// tracing (the driver-rt peer; needs DeviceCaps::driverRayTracing).
  bool driverTrace = false;
  bool aov = false;       ///< per-pixel gpu::TraceAov of the traced pixels
  ReadbackRequest readback;

  /// Two requests that compare equal draw the same image: a frame may reuse
  /// the last one (every field counts, so a new field can never reuse a stale image).
  friend bool operator==(const ViewRequest&, const ViewRequest&) = default;
};

/// What one frame did and skipped.
struct FrameStats {
  uint64_t frame = 0;
  uint32_t itemsDeformed = 0, itemsDeformSkipped = 0;
  uint32_t treesBuilt = 0, treesRefit = 0, treesSkipped = 0;  ///< bottom level
  uint64_t trianglesBuilt = 0, trianglesRefit = 0;
  uint32_t topLevelBuilt = 0, topLevelRefit = 0, topLevelSkipped = 0;
  uint32_t viewsRendered = 0, viewsSkipped = 0;
  uint32_t traceDispatches = 0;  ///< trace dispatches recorded (a masked one may find no pixel)
  uint64_t pixelsTraced = 0;     ///< counted on the GPU
  uint32_t dispatches = 0, draws = 0;
  uint32_t droppedTriangles = 0;  ///< non-finite triangles left out of this frame's trees
  bool rebased = false;           ///< the frame origin moved this frame
  /// The largest SAH cost of a refitted bottom-level tree over its cost just
  /// after its build (1: as good as new); past RendererOptions::rebuildGrowth it is rebuilt.
  double sahGrowth = 1.0;
};

/// A view's pixels as the frame left them, brought back when asked.
struct ViewPixels {
  uint32_t width = 0, height = 0;
  std::vector<glm::vec4> trace;      ///< the trace image, linear RGBA, row 0 at the top
  std::vector<glm::vec4> composite;  ///< composite views
  std::vector<gpu::TraceAov> aov;    ///< when asked for
  /// ReadbackRequest::half: the same images as 4 IEEE halves per pixel (then trace and composite stay empty).
  std::vector<uint16_t> traceHalf, compositeHalf;
};

struct FrameResult {
  FrameStats stats;
  std::vector<vk::PassTime> passes;
  std::vector<ViewPixels> views;  ///< per view asked to read back (empty otherwise)
};

/// What a frame is asked to do.
struct FrameRequest {
  const scene::Pose* pose = nullptr;
  std::vector<ViewRequest> views;
  /// Records work before the frame's own (a host's copy of new vertices into
  /// the buffers the frame reads); the frame's first barrier makes it visible.
  std::function<void(vk::Commands&)> prologue;
  /// Records more work after the views (a viewer's display pass and UI),
  /// once every view's images are written.
  std::function<void(vk::Commands&)> record;
  /// A swapchain's semaphores: waited for at `waitStage`, signalled at the end.
  VkSemaphore waitSemaphore = VK_NULL_HANDLE;
  VkPipelineStageFlags waitStage = 0;
  VkSemaphore signalSemaphore = VK_NULL_HANDLE;
};

struct RendererOptions {
  /// Frames the host records ahead of the GPU; host-written data has a copy per frame.
  uint32_t framesInFlight = 2;
  /// A refitted tree whose SAH cost has grown past this many times its cost
  /// after its last build is rebuilt.
  double rebuildGrowth = 1.5;
  /// Triangles rebuilt per frame at most (refitted meanwhile), so rebuilds spread over frames.
  uint64_t rebuildBudget = 1u << 20;
  /// A host scene's vertex buffers (every shape a host shape); null handles: none.
  HostBuffers host;
  /// GPU timestamps around every pass (FrameResult::passes); off, a frame records none.
  bool passTimes = true;
  /// Each frame as if it were the renderer's first: the origin at its camera,
  /// every tree built afresh. Its pixels then depend on nothing drawn before
  /// it, so a farm's chunks and retries agree bit for bit, for a build a frame.
  bool independentFrames = false;
};

/// The images of one view; they keep the last frame's result until the next frame that renders the view.
struct ViewImages {
  uint32_t width = 0, height = 0;
  vk::Image trace;           ///< rgba16f, storage
  vk::Image composite;       ///< kCompositeFormat (composite views)
  vk::Image depth, mask;     ///< the pre-pass's (composite views)
  vk::Buffer pixels;         ///< the masked trace's pixel list
  vk::Buffer aov;            ///< gpu::TraceAov per pixel, when asked for
};

class Renderer {
 public:
  /// Uploads the scene for the draw items of `pose`. Builds no tree and
  /// no trace pipeline until a frame needs them.
  Renderer(vk::Context& context, const scene::Scene& scene, const scene::Pose& pose, RendererOptions options = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Records and submits a frame and returns its number. Waits only for the
  /// frame that used its in-flight slot before (framesInFlight frames ago).
  uint64_t submit(const FrameRequest& request);
  /// Waits for frame `frame` (the most recent one framesInFlight can hold)
  /// and returns its results: the pixels asked for, what it did, pass times.
  const FrameResult& wait(uint64_t frame);
  /// Waits for every frame in flight.
  void finish();

  /// The images of view `index` (valid once a frame rendered it; a view's
  /// images are rewritten by later frames that render it).
  const ViewImages& viewImages(size_t index) const;

  /// The host rewrote shape `shape`'s vertices in its buffers (RendererOptions::host):
  /// the next frame refits its tree and redraws every view.
  void markDirty(int shape);
  /// A host shape's vertices now lie in this box (its space), for culling;
  /// an empty box (lo > hi) says nothing, and the shape is never culled.
  void setShapeBounds(int shape, const glm::dvec3& lo, const glm::dvec3& hi);

  /// Forces the next frame that needs trees to rebuild every tree.
  void invalidateTrees();
  /// The refraction-map method's map for view `view` of later frames: every
  /// pixel of `settings` traced at `pose` with its AOVs, and baked (waits for
  /// the GPU). The renderer keeps the last one baked per view on the GPU,
  /// which that view reads where its RasterOptions name no map of their own,
  /// and redraws the views with it; the bake itself goes to the caller.
  RefractionBake bakeRefractionMap(const scene::Pose& pose, const FrameSettings& settings, size_t view = 0);
  /// The map kept for view `view` (0 x 0 before one is baked).
  const RefractionMapBuffer& refractionMap(size_t view = 0) const;

  /// Forces the next frame to redraw every view, even one that nothing
  /// changed for (for tools that change GPU data behind the renderer's back).
  void invalidateViews();

  const SceneGpu& sceneGpu() const { return scene_; }
  const scene::Scene& scene() const { return sceneModel_; }
  const glm::dvec3& origin() const { return origin_.origin(); }
  /// Whether any face of the scene refracts or may be see-through by alpha
  /// (else a composite never traces).
  bool seeThrough() const { return seeThrough_; }
  /// The trees, built by the first frame that traces (null before).
  const Bvh* blas() const { return blas_.get(); }
  const Bvh* tlas() const { return tlas_.get(); }
  BvhBuilder* builder() { return builder_.get(); }
  /// The last update's instances (gpu::GpuInstance, rebased to the origin) and lights (gpu::GpuLight).
  const vk::Buffer& instances() const { return instances_; }
  const vk::Buffer& lights() const { return lights_; }
  uint32_t lightCount() const { return lightCount_; }
  /// GPU memory of geometry, deformation, trees and per-frame tables (not view images).
  uint64_t memoryBytes() const;
  /// The driver's statistics of the trace pipelines made so far (vk::ContextDesc::pipelineStatistics).
  std::vector<std::string> pipelineStatistics() const;
  /// Bytes of tree memory (both levels) per bottom-level triangle, build scratch apart.
  double treeBytesPerTriangle() const;

 private:
  struct Slot;
  struct View;
  struct Update;
  void prepareTrees();
  Update planUpdate(const scene::Pose& pose, const std::vector<ViewRequest>& views, FrameStats& stats);
  void recordUpdate(vk::Commands& commands, Slot& slot, const scene::Pose& pose, const Update& update);
  void recordView(vk::Commands& commands, Slot& slot, size_t index, const ViewRequest& request, FrameStats& stats);
  /// The view's trace, by snell's own traversal or (driverTrace) the driver's.
  void recordTrace(vk::Commands& commands, const ViewRequest& request, View& view, bool masked, FrameStats& stats);
  void collect(Slot& slot);
  bool viewNeedsTrees(const ViewRequest& request) const;
  bool transmissiveInView(const FrameSettings& settings) const;

  vk::Context& context_;
  const scene::Scene& sceneModel_;
  RendererOptions options_;
  SceneGpu scene_;
  std::unique_ptr<DeformPass> deform_;
  std::unique_ptr<RasterPass> raster_;
  std::unique_ptr<TracePass> trace_;
  std::unique_ptr<BvhBuilder> builder_;
  std::unique_ptr<Bvh> blas_, tlas_;
  vk::Buffer instances_, lights_;
  uint32_t lightCount_ = 0;
  bool seeThrough_ = false;
  std::vector<RefractionMapBuffer> maps_;  ///< per view index, baked by bakeRefractionMap

  // What the GPU holds, to find what changed.
  struct ItemState {
    bool deformed = false;
    std::vector<float> weights;
    std::vector<glm::dmat4> joints;
  };
  std::vector<ItemState> items_;           ///< per pose item
  std::vector<uint32_t> itemDeformOutput_; ///< per pose item: its DeformPass output, or ~0
  std::vector<gpu::GpuInstance> uploadedInstances_;
  std::vector<gpu::GpuLight> uploadedLights_;
  std::vector<char> geometryDirty_;  ///< per bottom-level group: positions changed since its tree last saw them
  bool treesBuilt_ = false, topDirty_ = true, topBuilt_ = false;
  uint64_t sceneVersion_ = 0;  ///< bumps whenever what a view shows may have changed
  SceneBounds bounds_;
  FrameOrigin origin_;
  RebuildQueue rebuilds_;

  std::vector<std::unique_ptr<Slot>> slots_;
  std::vector<View> views_;
  uint64_t submitted_ = 0;
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
  FrameStats stats;
};

/// Renders one view's trace of every pixel and reads it back (waits for the GPU).
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
/// on the host only (waits for the GPU), for a map file;
/// Renderer::bakeRefractionMap also keeps it on the GPU for the raster pass.
RefractionBake bakeRefraction(Renderer& renderer, const scene::Pose& pose, const FrameSettings& settings);

/// Checks a requested image size against the device: throws
/// std::invalid_argument saying what is wrong.
void checkImageSize(const vk::Context& context, uint32_t width, uint32_t height);

}  // namespace snell::render
