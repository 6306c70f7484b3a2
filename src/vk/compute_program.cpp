// Compute pipeline creation from reflected SPIR-V, and checked dispatches.
#include "vk/compute_program.h"

#include "vk/error.h"

#include <algorithm>


namespace snell::vk {

ComputeProgram::ComputeProgram(Context& context, const ComputeProgramDesc& desc)
    : context_(&context), name_(desc.name),
      reflection_(reflectProgramShader(desc.spirv, desc.specialization, desc.name)),
      layout_(context, desc.name, std::span(&desc.spirv, 1), {}, reflection_.bindings, VK_SHADER_STAGE_COMPUTE_BIT,
              reflection_.pushConstantBytes) {
  const DeviceCaps& caps = context.caps();
  uint64_t invocations = uint64_t(reflection_.localSize[0]) * reflection_.localSize[1] * reflection_.localSize[2];
  if (invocations > caps.maxComputeWorkgroupInvocations) {
    throw VulkanError("program '" + name_ + "' asks for workgroups of " + std::to_string(invocations) +
                      " invocations; the device allows " + std::to_string(caps.maxComputeWorkgroupInvocations));
  }
  if (desc.requireFullSubgroups && reflection_.localSize[0] % caps.maxSubgroupSize != 0) {
    throw VulkanError("program '" + name_ + "': full subgroups need a workgroup width that is a multiple of " +
                      std::to_string(caps.maxSubgroupSize));
  }

  uint32_t required = desc.requiredSubgroupSize;
  if (required && (required < caps.minSubgroupSize || required > caps.maxSubgroupSize || (required & (required - 1)))) {
    throw VulkanError("program '" + name_ + "' asks for subgroups of " + std::to_string(required) + " lanes; the device has " +
                      std::to_string(caps.minSubgroupSize) + "-" + std::to_string(caps.maxSubgroupSize));
  }
  VkPipelineShaderStageCreateFlags stageFlags =
      desc.requireFullSubgroups ? VK_PIPELINE_SHADER_STAGE_CREATE_REQUIRE_FULL_SUBGROUPS_BIT : 0;
  VkPipelineCreateFlags pipelineFlags = caps.pipelineStatistics ? VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR : 0;
  // The compile runs on its own thread; what it reads is copied into it or lives as long as this program.
  pipeline_.emplace(context, name_, [&context, module = layout_.module(0), layout = layout_.pipelineLayout(),
                                      specialization = Specialization(desc.specialization), stageFlags,
                                      pipelineFlags, required](VkPipeline* pipeline) mutable {
    VkPipelineShaderStageRequiredSubgroupSizeCreateInfo subgroupSize{
        VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_REQUIRED_SUBGROUP_SIZE_CREATE_INFO, nullptr, required};
    VkPipelineShaderStageCreateInfo stage{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    stage.pNext = required ? &subgroupSize : nullptr;
    stage.flags = stageFlags;
    stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    stage.module = module;
    stage.pName = "main";
    stage.pSpecializationInfo = specialization.info();
    VkComputePipelineCreateInfo pipelineInfo{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    pipelineInfo.flags = pipelineFlags;
    pipelineInfo.stage = stage;
    pipelineInfo.layout = layout;
    return vkCreateComputePipelines(context.device(), context.pipelineCache(), 1, &pipelineInfo, nullptr, pipeline);
  });
}

// The pipeline goes first (a compile still running finishes); the layout member retires the module and layouts after it.
ComputeProgram::~ComputeProgram() = default;

std::vector<PipelineStatistic> ComputeProgram::executableStatistics() const {
  return pipelineStatistics(*context_, pipeline_->get());
}

std::vector<std::string> ComputeProgram::statistics() const { return statisticLines(executableStatistics()); }

void ComputeProgram::record(Commands& commands, std::span<const BufferBinding> buffers, const void* push,
                            size_t pushBytes, uint64_t groups, const Buffer* indirect,
                            VkDeviceSize indirectOffset) const {
  layout_.checkPush(push, pushBytes);
  if (groups == 0 && !indirect) return;
  layout_.bind(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_->get(), buffers);
  layout_.push(commands, push);
  VkCommandBuffer cmd = commands.handle();
  commands.noteDispatch();
  if (indirect) {
    vkCmdDispatchIndirect(cmd, indirect->handle(), indirectOffset);
    return;
  }
  const DeviceCaps& caps = context_->caps();
  uint64_t maxX = caps.maxComputeWorkgroupCount[0];
  uint64_t x = std::min<uint64_t>(groups, maxX);
  uint64_t y = (groups + x - 1) / x;
  if (y > caps.maxComputeWorkgroupCount[1]) {
    throw VulkanError("program '" + name_ + "': " + std::to_string(groups) + " workgroups exceed the device's limits");
  }
  vkCmdDispatch(cmd, static_cast<uint32_t>(x), static_cast<uint32_t>(y), 1);
}

}  // namespace snell::vk
