// What a frame is asked to draw and what it gives back: the views (each an
// image of the scene at the frame's pose), the readbacks, and the frame's
// statistics and pixels. The Renderer (renderer.h) takes a FrameRequest and
// returns a FrameResult.
#pragma once

#include "render/frame_settings.h"
#include "render/raster_pass.h"
#include "scene/evaluate.h"
#include "shared/trace.h"
#include "vk/commands.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <functional>
#include <vector>

namespace snell::render {

enum class ViewOutput {
  Trace,      ///< every pixel traced (the CLI's default image, the golden tests)
  Composite,  ///< the viewport: raster pass, transmissive pixels traced
};

/// A view whose images (and AOV) come back to the host with its frame
/// (FrameResult::views, in FrameRequest::readbacks' order).
struct ReadbackRequest {
  size_t view = 0;  ///< index into FrameRequest::views
  /// Keep the images as the GPU's half floats (ViewPixels::*Half), for
  /// writers that convert them once, straight to the file's encoding.
  bool half = false;
  /// A composite's trace image too (off: the composite alone).
  bool trace = true;
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

  /// Two requests that compare equal draw the same image: a frame may reuse
  /// the last one (every field counts, so a new field can never reuse a stale image).
  friend bool operator==(const ViewRequest&, const ViewRequest&) = default;
};

/// What one frame did and skipped.
struct FrameStats {
  uint64_t frame = 0;
  uint32_t itemsDeformed = 0, itemsDeformSkipped = 0;
  uint32_t shapesCopied = 0;  ///< kept shapes whose rewritten vertices went to the GPU
  uint32_t shapesRefined = 0;  ///< subdivision surfaces whose moved cage the refine pass refined
  uint32_t verticesRefined = 0;  ///< the vertices those became
  uint32_t treesBuilt = 0, treesRefit = 0, treesSkipped = 0;  ///< bottom level
  uint64_t trianglesBuilt = 0, trianglesRefit = 0;
  uint32_t topLevelBuilt = 0, topLevelRefit = 0, topLevelSkipped = 0;
  uint32_t viewsRendered = 0, viewsSkipped = 0;
  uint32_t traceDispatches = 0;  ///< trace dispatches recorded (a masked one may find no pixel)
  uint64_t pixelsTraced = 0;     ///< counted on the GPU
  uint32_t traceLanes = 0;       ///< the most lanes a masked trace gave each pixel (0: no masked trace)
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
  std::vector<ViewPixels> views;  ///< per FrameRequest::readbacks entry, in its order
};

/// What a frame is asked to do.
struct FrameRequest {
  const scene::Pose* pose = nullptr;
  std::vector<ViewRequest> views;
  /// The views whose pixels come back with the frame.
  std::vector<ReadbackRequest> readbacks;
  /// Records more work after the views (a viewer's display pass and UI),
  /// once every view's images are written.
  std::function<void(vk::Commands&)> record;
  /// A swapchain's semaphores: waited for at `waitStage`, signalled at the end.
  VkSemaphore waitSemaphore = VK_NULL_HANDLE;
  VkPipelineStageFlags waitStage = 0;
  VkSemaphore signalSemaphore = VK_NULL_HANDLE;

  /// Throws std::invalid_argument (or the size check's error) for a request
  /// no renderer of `drawItems` draw items on `context` can draw: no pose or
  /// one of another scene, an image too large, a ray list that does not fill
  /// its view or that asks for a raster, a readback of a view not asked for.
  void check(const vk::Context& context, size_t drawItems) const;
};

}  // namespace snell::render
