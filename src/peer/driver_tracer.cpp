#include "peer/driver_tracer.h"

#include "peer/pass_names.h"
#include "vk/error.h"

#include "driver_trace.spv.h"
#include "driver_trace_hit.spv.h"
#include "driver_trace_miss.spv.h"

#include <cstddef>
#include <cstring>

namespace snell::peer {

namespace {

// The ray generation shader's push constants: the trace's, then the top level.
struct DriverTracePush {
  gpu::TracePush trace;
  VkDeviceAddress topLevel;
  uint64_t pad;
};
static_assert(offsetof(DriverTracePush, topLevel) == 128 && sizeof(DriverTracePush) == 144);

}  // namespace

vk::RayTracingProgramDesc DriverTracer::programDesc(uint32_t surface) {
  return {"driver trace", kSpvDriverTrace, kSpvDriverTraceMiss, kSpvDriverTraceHit, {{gpu::kTraceSpecSurface, surface}}};
}

DriverTracer::DriverTracer(vk::Context& context, const vk::Buffer& positions, uint32_t vertexCount,
                           const vk::Buffer& indices, const std::vector<DriverGeometry>& geometries,
                           uint32_t instanceCapacity, uint32_t surface)
    : context_(context) {
  if (!context.caps().driverRayTracing) {
    throw vk::VulkanError("driver-rt: this device offers no ray tracing pipelines (VK_KHR_ray_tracing_pipeline)");
  }
  std::vector<uint32_t> first;
  for (const DriverGeometry& g : geometries) {
    blas_.push_back(std::make_unique<DriverBlas>(context, positions, vertexCount, indices, g.triangleCount,
                                                 DriverBuild::FastTrace, g.firstTriangle));
    first.push_back(g.firstTriangle);
  }
  tlas_ = std::make_unique<DriverTlas>(context, instanceCapacity);
  program_ = std::make_unique<vk::RayTracingProgram>(context, programDesc(surface));
  geometryFirst_ = vk::Buffer(context, {std::max<size_t>(first.size(), 1) * 4,
                                        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                        vk::MemoryDomain::Device, "driver geometry first triangles"});
  if (!first.empty()) vk::upload(context, geometryFirst_, first.data(), first.size() * 4);
}

DriverTracer::~DriverTracer() = default;

uint64_t DriverTracer::bytes() const {
  uint64_t bytes = tlas_->bytes() + geometryFirst_.size();
  for (const auto& b : blas_) bytes += b->structureBytes() + b->scratchBytes();
  return bytes;
}

void DriverTracer::recordUpdate(vk::Commands& commands, vk::UploadArena& arena,
                                const std::vector<gpu::GpuInstance>& instances, bool instancesChanged,
                                const std::vector<uint32_t>& moved) {
  bool bottomChanged = !built_ || !moved.empty();
  if (!built_) {
    std::vector<DriverBlas*> all;
    for (auto& b : blas_) all.push_back(b.get());
    commands.beginPass(pass::kDriverBlasBuild);
    DriverBlas::recordBatch(commands, all, false);
    commands.endPass();
  } else if (!moved.empty()) {
    std::vector<DriverBlas*> some;
    for (uint32_t g : moved) some.push_back(blas_[g].get());
    commands.beginPass(pass::kDriverBlasUpdate);
    DriverBlas::recordBatch(commands, some, true);
    commands.endPass();
  }
  built_ = true;
  if (!bottomChanged && !instancesChanged) return;
  // Instance i is snell's instance i (its custom index), placed by the same rows.
  if (instances.size() > 0xffffffu) throw vk::VulkanError("driver-rt: more than 2^24 instances");
  std::vector<VkAccelerationStructureInstanceKHR> top(instances.size());
  for (size_t i = 0; i < instances.size(); ++i) {
    VkAccelerationStructureInstanceKHR& t = top[i];
    std::memcpy(&t.transform, &instances[i].objectToWorld, sizeof(t.transform));
    t.instanceCustomIndex = static_cast<uint32_t>(i) & 0xffffffu;  // 24 bits: capped below
    t.mask = 0xff;
    t.instanceShaderBindingTableRecordOffset = 0;
    // snell's single-sided faces (GpuInstance::flags) are culled as the trace
    // culls them. The driver decides facing in the instance's own space by
    // the same sign as glTF's counter-clockwise front (its "clockwise" is
    // seen in a left-handed frame; the DriverRt test measured the other choice
    // losing 25% of first hits), so a mirroring instance keeps its front, as
    // glTF asks, with no flag.
    const bool cull = (instances[i].flags & gpu::kInstanceCullBackFaces) != 0;
    t.flags = cull ? 0u : uint32_t(VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR);
    t.accelerationStructureReference = blas_.at(instances[i].geometry)->address();
  }
  commands.beginPass(pass::kDriverTlas);
  if (!top.empty()) arena.copy(commands, top, tlas_->instances());
  tlas_->recordBuild(commands, static_cast<uint32_t>(top.size()));
  commands.endPass();
}

void DriverTracer::recordTrace(vk::Commands& commands, std::span<const vk::BufferBinding> buffers,
                               const gpu::TracePush& push) {
  DriverTracePush p{push, tlas_->address(), 0};
  commands.beginPass(pass::kDriverTrace);
  program_->trace(commands, buffers, p, push.width, push.height);
  commands.endPass();
  // The image and AOV, written by ray tracing shaders, for whatever reads them next (readback, display).
  commands.barrier(VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, VK_ACCESS_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
}

}  // namespace snell::peer
