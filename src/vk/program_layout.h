// What every Vulkan program holds below its pipeline: its shader modules, the
// one descriptor set layout its reflected bindings make, and the pipeline
// layout with the push-constant range. The compute, graphics and ray tracing
// programs each add only their pipeline and how they record it.
#pragma once

#include "vk/commands.h"
#include "vk/context.h"
#include "vk/descriptors.h"
#include "vk/spirv_reflect.h"

#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace snell::vk {

/// Reflects one shader of program `name`; a module snell cannot read is a VulkanError.
ShaderReflection reflectProgramShader(std::span<const uint32_t> spirv, std::span<const SpecConstant> specialization,
                                      const std::string& name);

/// Specialisation constants as a stage's VkSpecializationInfo wants them; info() points into this object.
struct Specialization {
  explicit Specialization(std::span<const SpecConstant> constants);
  std::vector<VkSpecializationMapEntry> entries;
  std::vector<uint32_t> values;
  /// Null when there are none.
  const VkSpecializationInfo* info();

 private:
  VkSpecializationInfo info_{};
};

class ProgramLayout {
 public:
  /// Creates a module per SPIR-V blob (named "NAME" or "NAME STAGE" after
  /// `moduleNames`), the set layout of `bindings` for `stages`, and the
  /// pipeline layout. Push constants beyond the device's limit are a
  /// VulkanError naming the program.
  ProgramLayout(Context& context, const std::string& name, std::span<const std::span<const uint32_t>> spirv,
                std::span<const char* const> moduleNames, std::vector<ReflectedBinding> bindings,
                VkShaderStageFlags stages, uint32_t pushConstantBytes);
  /// Retires everything through the context, after the frames that use it.
  ~ProgramLayout();
  ProgramLayout(const ProgramLayout&) = delete;
  ProgramLayout& operator=(const ProgramLayout&) = delete;

  const std::string& name() const { return name_; }
  VkShaderModule module(size_t i) const { return modules_.at(i); }
  VkPipelineLayout pipelineLayout() const { return pipelineLayout_; }
  const std::vector<ReflectedBinding>& bindings() const { return bindings_; }
  uint32_t pushConstantBytes() const { return pushConstantBytes_; }

  /// Throws unless a call's push constants are the size the shaders declare
  /// (none at all also fits a program without push constants).
  void checkPush(const void* push, size_t pushBytes) const;
  /// Binds `pipeline` and a descriptor set holding `resources`, one per binding.
  void bind(Commands& commands, VkPipelineBindPoint point, VkPipeline pipeline,
            std::span<const BufferBinding> resources) const;
  /// Pushes the program's push constants (nothing when it declares none).
  void push(Commands& commands, const void* data) const;

 private:
  Context* context_;
  std::string name_;
  std::vector<ReflectedBinding> bindings_;
  VkShaderStageFlags stages_;
  uint32_t pushConstantBytes_;
  std::vector<VkShaderModule> modules_;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout pipelineLayout_ = VK_NULL_HANDLE;
};

}  // namespace snell::vk
