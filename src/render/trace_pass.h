// The trace pass: one ray per pixel (or per listed pixel of the masked
// viewport) through the two-level tree, refracted, reflected and shaded by
// the rules of shaders/shared/trace.h, and its peer through the driver's own
// ray tracing (driver-rt). The Renderer lends it the scene, the trees and the
// view's images each frame; it owns what only tracing needs: the trace
// pipelines, specialised to the optics a view asks for and the scene can show
// and to the surface features its materials use (a feature the scene lacks
// compiles out, the driver's pipeline's too), the compaction of the masked
// trace's pixel list, the environments reflected rays see, and the driver's
// structures with what they have seen.
#pragma once

#include "peer/driver_tracer.h"
#include "render/bvh.h"
#include "render/frame_settings.h"
#include "render/scene_gpu.h"
#include "scene/scene.h"
#include "shared/trace.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/compute_program.h"
#include "vk/context.h"
#include "vk/upload_arena.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <map>
#include <memory>
#include <vector>

namespace snell::render {

/// What a trace reads from the frame: the scene as the update left it.
struct TraceInputs {
  const SceneGpu* scene = nullptr;
  const vk::Buffer* instances = nullptr;  ///< gpu::GpuInstance, rebased to `origin`
  const vk::Buffer* lights = nullptr;     ///< gpu::GpuLight
  uint32_t lightCount = 0;
  glm::dvec3 origin{0.0};  ///< the frame origin everything is relative to
  const Bvh* blas = nullptr;
  const Bvh* tlas = nullptr;
};

/// Where one view's trace writes.
struct TraceTarget {
  const vk::Image* image = nullptr;   ///< rgba16f storage image
  const vk::Buffer* aov = nullptr;    ///< gpu::TraceAov per pixel; null: none written
  const vk::Buffer* rays = nullptr;   ///< the view's listed primary rays (FrameSettings::rays); null: camera rays
  const vk::Image* mask = nullptr;    ///< masked: the raster pre-pass's transmissive mask
  const vk::Buffer* pixels = nullptr; ///< masked: the pixel list the compaction writes
};

class TracePass {
 public:
  /// `childBoxes`: what the scene's trees keep for the walk (SceneTrees' forests); `wideWalk`: whether
  /// the bottom level keeps 4-wide records (keepsWideRecords), which the walk then reads.
  TracePass(vk::Context& context, const scene::Scene& scene, const SceneGpu& gpu, BvhChildBoxes childBoxes,
            bool wideWalk);
  ~TracePass();
  TracePass(const TracePass&) = delete;
  TracePass& operator=(const TracePass&) = delete;

  /// Uploads the environment `settings` reflects, once per environment (before recording).
  void prepare(const FrameSettings& settings);
  /// Starts compiling the pipeline a trace of `settings` needs, so the
  /// compile runs beside the frame's other work (Context::compileAsync).
  void prefetch(const FrameSettings& settings, bool aov, bool masked);
  /// Records one view's trace: every pixel, or (masked) the pixels the mask
  /// marks, compacted first into the pixel list. Returns the pixels traced
  /// when the host knows them (unmasked), else 0 (the GPU counts them).
  uint64_t record(vk::Commands& commands, const TraceInputs& in, const FrameSettings& settings,
                  const TraceTarget& target, bool masked, uint32_t lanes = 1);
  /// The lanes that trace each listed pixel of a masked trace: 1, 2, 4 or 8,
  /// no wider than the device's smallest subgroup. `forced` (non-zero) wins.
  /// Otherwise the pixels the view's last masked trace listed choose (0: not
  /// known, one lane): as many lanes as keep pixels x lanes within
  /// kMaskedLaneInvocations, since a few rays leave the GPU waiting on each
  /// ray's chain of node visits. A choice whose pipeline is still compiling
  /// starts it and draws this frame with one lane.
  uint32_t maskedLanes(const FrameSettings& settings, bool aov, uint64_t listedBefore, uint32_t forced);
  /// Measured on an H100 (bench/results/trace-1.5x.md, step 4): 5.4k pixels
  /// traced fastest with 8 lanes, 43k with 2, 136k with 1.
  static constexpr uint64_t kMaskedLaneInvocations = 96 * 1024;

  /// The driver-rt peer. The renderer says which geometries deformed and
  /// whether instances moved since the driver's structures last saw them;
  /// the frames that trace through the driver bring them up to date first.
  void noteGeometryMoved(uint32_t geometry) { driverMoved_.at(geometry) = 1; }
  void noteInstancesMoved() { driverInstancesStale_ = true; }
  void recordDriverUpdate(vk::Commands& commands, vk::UploadArena& arena, const SceneGpu& gpu,
                          const std::vector<gpu::GpuInstance>& instances, bool instancesChanged);
  uint64_t recordDriver(vk::Commands& commands, const TraceInputs& in, const FrameSettings& settings,
                        const TraceTarget& target);

  /// The trace pipeline specialised to the optics a view traces with
  /// (gpu::kOptics*), its flags (gpu::kTraceFlag*), the lanes a pixel and the
  /// surface features a scene's materials use (gpu::kSurface*), for trees
  /// with `childBoxes` and, with `wideWalk`, 4-wide records, as every trace
  /// pass makes it on `device`; and the masked trace's compaction.
  static vk::ComputeProgramDesc programDesc(const vk::DeviceFacts& device, uint32_t optics, uint32_t flags,
                                            uint32_t lanes, uint32_t surface,
                                            BvhChildBoxes childBoxes = BvhChildBoxes::Exact, bool wideWalk = true);
  /// Whether the several-lanes walk must be compiled for 32-lane subgroups:
  /// on AMD's RDNA1 and RDNA2 (gfx10) through RADV. Mesa 22.3's compiler
  /// (Debian 12's) corrupts its own heap compiling it in wave64, the default
  /// (`snell bench pipelines --amd gfx1030`: every gfx10 part aborts, gfx9
  /// and gfx11 compile, and so does wave32, which the walk allows).
  static bool manyLanesNeedWave32(const vk::DeviceFacts& device);
  static vk::ComputeProgramDesc compactDesc();

  /// The optics bits (gpu::kOptics*) a view of `settings` traces with: those it asks for that the scene can show.
  uint32_t opticsFor(const FrameSettings& settings) const;
  /// The driver's statistics of each trace pipeline made so far (registers,
  /// spills, ...), one line each, where the context captures them.
  std::vector<std::string> statistics() const;
  /// Waits for every trace pipeline made so far, lane choices' included.
  void finishCompiles() const;
  /// GPU memory of the driver's structures (the environments are the views' own).
  uint64_t bytes() const;
  /// A small buffer bound where a view has no AOV, ray list or pixel list.
  const vk::Buffer& placeholder() const { return placeholder_; }

 private:
  gpu::TracePush push(const TraceInputs& in, const FrameSettings& settings, const TraceTarget& target,
                      bool masked) const;
  std::vector<vk::BufferBinding> pathBindings(const TraceInputs& in, const FrameSettings& settings,
                                              const TraceTarget& target) const;
  const vk::Buffer& environmentBuffer(const scene::Optics& optics) const;
  /// The trace pipeline specialised to `optics` and `flags` (gpu::kTraceFlag*), made on first use.
  const vk::ComputeProgram& program(uint32_t optics, uint32_t flags, uint32_t lanes);
  uint32_t flagsFor(const FrameSettings& settings, bool aov, bool masked) const;
  static uint32_t replayFlags(const FrameSettings& settings);
  /// The hit records a record or replay binds (made by the first record), else the placeholder.
  const vk::Buffer& hitRecords(const FrameSettings& settings);

  vk::Context& context_;
  uint32_t sceneOptics_ = 0;  ///< gpu::kOptics* bits the scene's materials can show
  uint32_t sceneSurface_ = 0;  ///< gpu::kSurface* bits its materials use (SceneGpu::surface)
  BvhChildBoxes childBoxes_;
  bool wideWalk_;
  std::map<uint64_t, std::unique_ptr<vk::ComputeProgram>> programs_;  ///< by optics << 32 | lanes << 16 | flags
  std::unique_ptr<vk::ComputeProgram> compact_;
  vk::Buffer placeholder_;
  vk::Buffer hitRecords_;  ///< the hit-replay ablation's records (FrameSettings::hitReplay)
  /// Environments uploaded for views, by identity; each holds its own reference,
  /// so a buffer is never freed under a frame in flight that reads it.
  struct Environment {
    std::shared_ptr<const scene::Environment> source;
    vk::Buffer buffer;
  };
  std::map<const scene::Environment*, Environment> environments_;
  std::unique_ptr<peer::DriverTracer> driver_;  ///< made when a view first asks for driver-rt
  std::vector<char> driverMoved_;               ///< per geometry: positions changed since the driver's structures saw them
  bool driverInstancesStale_ = true;            ///< instances moved in frames the driver's top level did not see
};

}  // namespace snell::render
