// A ray tracing pipeline (VK_KHR_ray_tracing_pipeline) of one ray generation,
// one miss and one closest-hit shader, with its shader binding table, built
// from embedded SPIR-V that knows its own bindings like ComputeProgram. Only
// where DeviceCaps::driverRayTracing: the driver-rt method's peer pipeline.
#pragma once

#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/descriptors.h"
#include "vk/pipeline_statistics.h"
#include "vk/program_layout.h"
#include "vk/spirv_reflect.h"

#include <vulkan/vulkan.h>

#include <initializer_list>
#include <span>
#include <string>
#include <vector>

namespace snell::vk {

struct RayTracingProgramDesc {
  std::string name;
  std::span<const uint32_t> raygen, miss, closestHit;
  std::vector<SpecConstant> raygenSpecialization;  ///< the ray generation shader's specialisation constants
};

class RayTracingProgram {
 public:
  RayTracingProgram(Context& context, const RayTracingProgramDesc& desc);
  ~RayTracingProgram();
  RayTracingProgram(const RayTracingProgram&) = delete;
  RayTracingProgram& operator=(const RayTracingProgram&) = delete;

  /// The driver's statistics of each of its shaders (empty unless the context captures statistics).
  std::vector<PipelineStatistic> executableStatistics() const;

  /// Launches width x height ray generation invocations.
  template <typename Push>
  void trace(Commands& commands, std::span<const BufferBinding> buffers, const Push& push, uint32_t width,
             uint32_t height) const {
    record(commands, buffers, &push, sizeof(Push), width, height);
  }

 private:
  void record(Commands& commands, std::span<const BufferBinding> buffers, const void* push, size_t pushBytes,
              uint32_t width, uint32_t height) const;

  Context* context_;
  std::string name_;
  ProgramLayout layout_;  ///< the ray generation shader's bindings: only it binds resources
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  Buffer table_;
  VkStridedDeviceAddressRegionKHR raygenRegion_{}, missRegion_{}, hitRegion_{}, callableRegion_{};
  PFN_vkCmdTraceRaysKHR traceRays_ = nullptr;
};

}  // namespace snell::vk
