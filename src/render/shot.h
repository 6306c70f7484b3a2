// A shot: frames of one scene, drawn on one device or several. One worker
// per device, each with its own Vulkan context, scene upload and trees, takes
// frames from one queue, so a slower device takes fewer, and a worker whose
// device is lost hands its frame back to the others. Every frame is drawn as
// if it were its renderer's first (RendererOptions::independentFrames), so
// its pixels do not depend on which worker drew it, nor on the frames before.
//
// The caller feeds the frames and takes the finished ones on its own thread
// (a Python host's, a DCC's main thread, whose own data is not for other
// threads), or lets each worker hand over its frames as they finish (files
// encoded in parallel). `snell render`, libsnell's renderFrames, Python's
// snell.render_frames and the Blender add-on's animation render all draw
// their frames here.
#pragma once

#include "render/frame_request.h"
#include "render/frame_settings.h"
#include "render/raster_pass.h"
#include "render/refraction_map.h"
#include "scene/evaluate.h"
#include "scene/scene.h"
#include "scene/view.h"
#include "shared/trace.h"
#include "vk/commands.h"
#include "vk/context.h"

#include <glm/glm.hpp>

#include <csignal>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace snell::render {

/// One frame of a shot: a time in the scene's animation, and what the host
/// changes at it (a DCC's own animation: transforms, rewritten vertices, its camera).
struct ShotFrame {
  long number = 0;
  double seconds = 0.0;
  std::optional<scene::View> view;  ///< none: ShotSettings::view at the frame's pose
  /// Draw item i's world matrix, over the scene's own pose.
  std::vector<std::pair<size_t, glm::dmat4>> transforms;
  /// A kept shape's vertices (ShotSettings::keepVertices), packed float triples.
  /// Each worker keeps what the frames it drew gave: a shape that one frame
  /// rewrites should come in every frame, or a frame's pixels would depend
  /// on which worker drew it.
  struct Vertices {
    int shape = 0;
    std::vector<float> positions, normals;
  };
  std::vector<Vertices> vertices;
};

/// What every frame of the shot shares.
struct ShotSettings {
  /// Each frame's settings (size, background, interfaces, optics), its
  /// camera apart: the frame's own, or `view`'s at its pose.
  FrameSettings frame;
  /// The camera at a frame's pose where the frame names none.
  std::function<scene::View(const scene::Pose&)> view;
  /// auto or one of methods(); auto on more than one worker is trace (each
  /// device could time the two differently, and a shot's frames must agree).
  std::string method = "auto";
  bool viewport = false;  ///< the composite is the picture (a traced method traces the glass pixels alone)
  RasterOptions raster;
  /// The trace's per-pixel data (gpu::TraceAov) with each frame, where the method traces every pixel itself.
  bool aov = false;
  /// refraction-map: the seconds its map is baked at, by each worker when it opens.
  double bakeTime = 0.0;
  /// GPU timestamps around every pass (ShotImage::passes, ShotWorker::treeMs).
  bool passTimes = false;
  /// How many frames the shot has, where known: auto does not time a short one.
  uint64_t frames = UINT64_MAX;
  /// Frames rewrite shapes' vertices (ShotFrame::vertices; RendererOptions::keepVertices).
  bool keepVertices = false;
};

/// A frame drawn, as the shot hands it over.
struct ShotImage {
  ShotFrame frame;
  size_t worker = 0;
  std::string device;
  std::string why;  ///< how the worker's device was chosen
  const vk::DeviceFacts* facts = nullptr;  ///< the worker's device (valid during ShotIo::done)
  scene::Pose pose;
  scene::View view;
  std::string method;      ///< what drew it
  std::string methodLine;  ///< what auto chose and why, or the method and its summary
  double drawSeconds = 0.0;  ///< from taking the frame to handing it over
  bool composite = false;  ///< the picture is the composite (else the trace image)
  ViewPixels pixels;       ///< the picture as half floats (and the AOV where asked)
  FrameStats stats;
  std::vector<vk::PassTime> passes;

  const std::vector<uint16_t>& rgbaHalf() const { return composite ? pixels.compositeHalf : pixels.traceHalf; }
};

/// What one worker did.
struct ShotWorker {
  std::string device;
  std::string why;           ///< how its device was chosen
  size_t frames = 0;
  double loadSeconds = 0.0;  ///< its device, the scene's upload and pipelines, before its first frame
  double treeMs = 0.0;       ///< GPU time building trees (with passTimes)
  double gpuWaitSeconds = 0.0;  ///< waiting for its frames' GPU work
  double sinkSeconds = 0.0;     ///< in ShotIo::done (where the workers call it)
  uint64_t validationMessages = 0;
  std::string lost;  ///< why its device stopped early ("" when it ran to the end)
  std::string method;  ///< what its frames were drawn with, and (auto) why
};

struct ShotReport {
  std::vector<ShotWorker> workers;
  double seconds = 0.0;  ///< from the start to the last frame handed over, loads included
  size_t frames = 0;     ///< frames handed over
  bool stopped = false;  ///< ShotIo::stop ended it; the frames under way were dropped
};

/// Where the frames come from and go.
struct ShotIo {
  /// The next frame, or none when there are no more; on the calling thread.
  std::function<std::optional<ShotFrame>()> next;
  /// A frame drawn: on the calling thread, or (sinkOnWorkers) on its
  /// worker's, one frame per worker at a time, so it must be thread-safe.
  std::function<void(ShotImage&&)> done;
  bool sinkOnWorkers = false;
  /// A worker opened its device (ShotWorker::device and why say which); on its thread.
  std::function<void(size_t worker, const ShotWorker& opened)> opened;
  /// A worker baked the refraction-map method's map; on its thread.
  std::function<void(size_t worker, const RefractionBake& bake)> baked;
  /// Polled: once non-zero, the shot ends after the frames under way, which are dropped.
  const volatile std::sig_atomic_t* stop = nullptr;
};

/// A worker's device: an override for vk::ContextDesc::deviceOverride ("":
/// the context's own choice) and how it was chosen.
struct ShotDevice {
  std::string override;
  std::string why;
};

/// The workers of a --devices list (vk::devicesForList), or with no list one
/// worker on the device `single` names ("": snell's own choice).
std::vector<ShotDevice> shotDevices(const std::string& list, const vk::DeviceEnvironment& environment,
                                    const std::string& single = "");

/// Draws every frame `io.next` gives, with one worker per entry of
/// `devices` (an entry twice: two workers on one device), each made from
/// `context`. Throws the first error every device would meet; a lost
/// device's frames go to the others, and its error is thrown only when no
/// worker is left to draw them.
ShotReport renderShot(const scene::Scene& scene, const ShotSettings& settings, const vk::ContextDesc& context,
                      const std::vector<ShotDevice>& devices, const ShotIo& io);

/// Whether a pass builds or refits trees (or sorts for them): ShotWorker::treeMs.
bool isTreePass(const std::string& name);

}  // namespace snell::render
