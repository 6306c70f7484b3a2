// The driver-rt method: the scene's deformed triangles in the driver's own
// acceleration structures (one bottom level per geometry, updated in place
// when it deforms; a top level rebuilt when anything moved) and traced by a
// ray tracing pipeline running trace.comp's own path code. The Renderer owns
// one when a view asks for it; only where DeviceCaps::driverRayTracing.
#pragma once

#include "peer/driver_bvh.h"
#include "shared/bvh.h"
#include "shared/trace.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/ray_tracing_program.h"
#include "vk/upload_arena.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace snell::peer {

/// One geometry's triangles: a range of the scene's index buffer.
struct DriverGeometry {
  uint32_t firstTriangle = 0, triangleCount = 0;
};

class DriverTracer {
 public:
  /// `positions` and `indices` need kDriverInputUsage and device addresses.
  /// `surface`: the gpu::kSurface* bits the scene's materials use; the path
  /// code compiles out the rest, as the trace's does (kTraceSpecSurface).
  DriverTracer(vk::Context& context, const vk::Buffer& positions, uint32_t vertexCount, const vk::Buffer& indices,
               const std::vector<DriverGeometry>& geometries, uint32_t instanceCapacity, uint32_t surface);
  ~DriverTracer();

  /// Its ray tracing pipeline for a scene whose materials use `surface`.
  static vk::RayTracingProgramDesc programDesc(uint32_t surface);

  /// Builds every bottom level the first time, then updates the `moved`
  /// geometries in place, and rebuilds the top level over `instances` when
  /// either changed or `instancesChanged`. Passes: driver blas build, driver
  /// blas update, driver tlas.
  void recordUpdate(vk::Commands& commands, vk::UploadArena& arena, const std::vector<gpu::GpuInstance>& instances,
                    bool instancesChanged, const std::vector<uint32_t>& moved);
  /// Traces width x height pixels with `push` (pass: driver trace).
  void recordTrace(vk::Commands& commands, std::span<const vk::BufferBinding> buffers, const gpu::TracePush& push);
  const vk::Buffer& geometryFirst() const { return geometryFirst_; }
  uint64_t bytes() const;

 private:
  vk::Context& context_;
  std::vector<std::unique_ptr<DriverBlas>> blas_;
  std::unique_ptr<DriverTlas> tlas_;
  std::unique_ptr<vk::RayTracingProgram> program_;
  vk::Buffer geometryFirst_;
  bool built_ = false;
};

}  // namespace snell::peer
