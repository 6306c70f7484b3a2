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
#include "render/frame_request.h"
#include "render/frame_settings.h"
#include "render/raster_pass.h"
#include "render/refraction_map.h"
#include "render/scene_gpu.h"
#include "render/scene_state.h"
#include "render/scene_trees.h"
#include "render/trace_pass.h"
#include "render/vertex_feed.h"
#include "render/view_targets.h"
#include "scene/evaluate.h"
#include "scene/scene.h"
#include "shared/trace.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/context.h"

#include <glm/glm.hpp>

#include <memory>
#include <string>
#include <vector>

namespace snell::render {

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
  /// Keep a host copy of every static shape's vertices for the caller to
  /// rewrite (Renderer::keptVertices, then markDirty): the next frame copies
  /// what changed to the GPU before its own work.
  bool keepVertices = false;
  /// GPU timestamps around every pass (FrameResult::passes); off, a frame records none.
  bool passTimes = true;
  /// Each frame as if it were the renderer's first: the origin at its camera,
  /// every tree built afresh. Its pixels then depend on nothing drawn before
  /// it, so a farm's chunks and retries agree bit for bit, for a build a frame.
  bool independentFrames = false;
  /// Lanes that trace each pixel of a masked trace: 0 chooses from the
  /// view's last count of glass pixels (TracePass::maskedLanes); 1, 2, 4 or 8
  /// (no wider than the device's smallest subgroup) fixes it, for benchmarks
  /// and tests. Independent frames, which know no last count, use one.
  uint32_t traceLanes = 0;
  /// Trees of 40 bytes a triangle: the walk decodes each node's 8-bit
  /// quantised child boxes. Off, the trees also keep every node's children's
  /// exact boxes and a bottom level's 4-wide records (216 bytes a triangle),
  /// and the walk reads those 4 wide and decodes nothing
  /// (bench/results/walk-counts.md: how much faster).
  bool compactTrees = false;
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
  const ViewImages& viewImages(size_t index) const { return targets_.images(index); }

  /// Static shape `shape`'s vertices as the renderer keeps them
  /// (RendererOptions::keepVertices). Waits for the frames in flight, so
  /// none reads them while the caller rewrites them.
  KeptVertices keptVertices(int shape);
  /// Shape `shape`'s vertices changed (kept ones, or the host's in its own
  /// buffers): the next frame copies kept ones, refits its tree and redraws
  /// every view. A shape without a host's promised box is not culled until a
  /// refit has measured its new box.
  void markDirty(int shape);

  /// The refraction-map method's map for view `view` of later frames: every
  /// pixel of `settings` traced at `pose` with its AOVs, and baked (waits for
  /// the GPU). The renderer keeps the last one baked per view on the GPU,
  /// which that view reads where its RasterOptions name no map of their own,
  /// and redraws the views with it; the bake itself goes to the caller.
  RefractionBake bakeRefractionMap(const scene::Pose& pose, const FrameSettings& settings, size_t view = 0);
  /// The refraction-map method's map for view `view`, baked from `settings`
  /// at `pose` unless one of the view's size is kept: baked once, it is read
  /// as the scene moves on (a caller that wants a new pose bakes anew). The
  /// bake where it baked.
  std::optional<RefractionBake> keepRefractionMap(const scene::Pose& pose, const FrameSettings& settings, size_t view = 0);
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
  const Bvh* blas() const { return trees_.blas(); }
  const Bvh* tlas() const { return trees_.tlas(); }
  BvhBuilder* builder() { return trees_.builder(); }
  /// GPU memory of geometry, deformation, trees and per-frame tables (not view images).
  uint64_t memoryBytes() const;
  /// The driver's statistics of the trace pipelines made so far (vk::ContextDesc::pipelineStatistics).
  std::vector<std::string> pipelineStatistics() const;
  /// Waits for the trace pipelines still compiling beside the frames (a
  /// wider masked trace's among them), so that the next frames draw as a
  /// long session's do: for benchmarks, after their warm-up.
  void finishCompiles() const;
  /// Bytes of tree memory (both levels) per bottom-level triangle, build scratch apart.
  double treeBytesPerTriangle() const { return trees_.treeBytesPerTriangle(); }

 private:
  struct Slot;
  struct ViewPlan;
  struct ViewState;
  struct Update;
  ViewPlan plan(const ViewRequest& request) const;
  Update planUpdate(const scene::Pose& pose, const FrameRequest& request, const std::vector<ViewPlan>& plans,
                    Slot& slot);
  void planDeform(const scene::Pose& pose, Update& update, FrameStats& stats);
  void recordUpdate(vk::Commands& commands, Slot& slot, const scene::Pose& pose, const Update& update);
  void recordView(vk::Commands& commands, Slot& slot, size_t index, const ViewRequest& request, const ViewPlan& plan);
  /// The view's trace, by snell's own traversal or (plan.driver) the driver's.
  void recordTrace(vk::Commands& commands, size_t index, const ViewRequest& request, const ViewPlan& plan,
                   FrameStats& stats);
  void recordReadbacks(vk::Commands& commands, Slot& slot, const FrameRequest& request);
  void recordStatistics(vk::Commands& commands, Slot& slot, size_t views);
  void collect(Slot& slot);
  /// Bottom-level group `geometry`'s positions changed.
  void noteMoved(uint32_t geometry);

  vk::Context& context_;
  const scene::Scene& sceneModel_;
  RendererOptions options_;
  SceneGpu scene_;
  std::unique_ptr<DeformPass> deform_;
  std::unique_ptr<VertexFeed> feed_;  ///< kept vertices, host copies and the refine
  std::unique_ptr<RasterPass> raster_;
  std::unique_ptr<TracePass> trace_;
  SceneTrees trees_;
  vk::Buffer instances_, lights_;
  uint32_t lightCount_ = 0;
  bool seeThrough_ = false;
  std::vector<RefractionMapBuffer> maps_;  ///< per view index, baked by bakeRefractionMap
  ViewTargets targets_;
  std::vector<ViewState> views_;  ///< per view index: what it last drew

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
  uint64_t sceneVersion_ = 0;  ///< bumps whenever what a view shows may have changed
  SceneBounds bounds_;
  FrameOrigin origin_;

  std::vector<std::unique_ptr<Slot>> slots_;
  uint64_t submitted_ = 0;
};

}  // namespace snell::render
