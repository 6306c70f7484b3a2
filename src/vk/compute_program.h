// A compute pipeline built from embedded SPIR-V that knows its own layout:
// workgroup size, bindings and push-constant size come from reflection, so call
// sites give thread counts and buffers, never group counts or binding tables.
#pragma once

#include "vk/async_pipeline.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/descriptors.h"
#include "vk/pipeline_statistics.h"
#include "vk/program_layout.h"
#include "vk/spirv_reflect.h"

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace snell::vk {

struct ComputeProgramDesc {
  std::string name;
  std::span<const uint32_t> spirv;
  std::vector<SpecConstant> specialization;
  /// Every subgroup is full and the subgroup numbering is dense; needed by
  /// shaders that rank or scan in (gl_SubgroupID, gl_SubgroupInvocationID) order.
  bool requireFullSubgroups = false;
  /// Compile for subgroups of exactly this many lanes (VK_EXT_subgroup_size_control,
  /// core in 1.3), within the device's range; 0: the driver's choice. The
  /// renderer leaves it to the driver; `snell bench pipelines --wave32` asks.
  uint32_t requiredSubgroupSize = 0;
};

class ComputeProgram {
 public:
  ComputeProgram(Context& context, const ComputeProgramDesc& desc);
  ~ComputeProgram();
  ComputeProgram(const ComputeProgram&) = delete;
  ComputeProgram& operator=(const ComputeProgram&) = delete;

  const std::string& name() const { return name_; }
  std::array<uint32_t, 3> localSize() const { return reflection_.localSize; }
  const ShaderReflection& reflection() const { return reflection_; }
  /// "name = value" lines the driver reports for this pipeline (registers,
  /// spills, ...); empty unless the context captures pipeline statistics.
  std::vector<std::string> statistics() const;
  /// The same, one entry per statistic (waits for the compile).
  std::vector<PipelineStatistic> executableStatistics() const;
  /// Its compile has finished (so a dispatch does not wait for it).
  bool ready() const { return pipeline_->ready(); }
  /// Waits for its compile (and throws what the compile threw).
  void finishCompile() const { pipeline_->get(); }

  /// Dispatches enough workgroups to cover `threads` invocations along x.
  template <typename Push>
  void dispatchThreads(Commands& commands, std::initializer_list<BufferBinding> buffers, const Push& push,
                       uint64_t threads) const {
    dispatchThreads(commands, std::span(buffers.begin(), buffers.size()), push, threads);
  }
  template <typename Push>
  void dispatchThreads(Commands& commands, std::span<const BufferBinding> buffers, const Push& push,
                       uint64_t threads) const {
    uint64_t groups = (threads + reflection_.localSize[0] - 1) / reflection_.localSize[0];
    record(commands, buffers, &push, sizeof(Push), groups);
  }
  /// Dispatches `groups` workgroups; above the device's x limit they are split
  /// over y, and shaders flatten (x, y) back into one block index.
  template <typename Push>
  void dispatchGroups(Commands& commands, std::initializer_list<BufferBinding> buffers, const Push& push,
                      uint64_t groups) const {
    record(commands, std::span(buffers.begin(), buffers.size()), &push, sizeof(Push), groups);
  }
  template <typename Push>
  void dispatchGroups(Commands& commands, std::span<const BufferBinding> buffers, const Push& push,
                      uint64_t groups) const {
    record(commands, buffers, &push, sizeof(Push), groups);
  }
  /// Dispatches the workgroup counts (x, y, z) the GPU wrote at `offset` of
  /// `arguments` (VkDispatchIndirectCommand), made visible to the indirect stage before.
  template <typename Push>
  void dispatchIndirect(Commands& commands, std::span<const BufferBinding> buffers, const Push& push,
                        const Buffer& arguments, VkDeviceSize offset = 0) const {
    record(commands, buffers, &push, sizeof(Push), 0, &arguments, offset);
  }

 private:
  void record(Commands& commands, std::span<const BufferBinding> buffers, const void* push, size_t pushBytes,
              uint64_t groups, const Buffer* indirect = nullptr, VkDeviceSize indirectOffset = 0) const;

  Context* context_;
  std::string name_;
  ShaderReflection reflection_;
  ProgramLayout layout_;
  std::optional<AsyncPipeline> pipeline_;  ///< after layout_: it goes first, then the modules it reads
};

}  // namespace snell::vk
