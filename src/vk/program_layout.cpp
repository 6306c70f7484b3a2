#include "vk/program_layout.h"

#include "vk/error.h"

#include <stdexcept>

namespace snell::vk {

ShaderReflection reflectProgramShader(std::span<const uint32_t> spirv, std::span<const SpecConstant> specialization,
                                      const std::string& name) {
  try {
    return reflectShader(spirv, specialization, name);
  } catch (const std::runtime_error& e) {
    throw VulkanError(e.what());
  }
}

Specialization::Specialization(std::span<const SpecConstant> constants) {
  for (const SpecConstant& s : constants) {
    entries.push_back({s.id, static_cast<uint32_t>(values.size() * sizeof(uint32_t)), sizeof(uint32_t)});
    values.push_back(s.value);
  }
}

const VkSpecializationInfo* Specialization::info() {
  if (entries.empty()) return nullptr;
  info_ = {static_cast<uint32_t>(entries.size()), entries.data(), values.size() * sizeof(uint32_t), values.data()};
  return &info_;
}

ProgramLayout::ProgramLayout(Context& context, const std::string& name,
                             std::span<const std::span<const uint32_t>> spirv, std::span<const char* const> moduleNames,
                             std::vector<ReflectedBinding> bindings, VkShaderStageFlags stages,
                             uint32_t pushConstantBytes)
    : context_(&context), name_(name), bindings_(std::move(bindings)), stages_(stages),
      pushConstantBytes_(pushConstantBytes) {
  if (pushConstantBytes_ > context.caps().maxPushConstantsSize) {
    throw VulkanError("program '" + name_ + "' has " + std::to_string(pushConstantBytes_) +
                      " bytes of push constants; the device allows " + std::to_string(context.caps().maxPushConstantsSize));
  }
  VkDevice device = context.device();
  try {
    for (size_t i = 0; i < spirv.size(); ++i) {
      VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
      info.codeSize = spirv[i].size_bytes();
      info.pCode = spirv[i].data();
      VkShaderModule module = VK_NULL_HANDLE;
      VK_CHECK(vkCreateShaderModule(device, &info, nullptr, &module));
      modules_.push_back(module);
      const char* stage = i < moduleNames.size() ? moduleNames[i] : nullptr;
      context.setName(VK_OBJECT_TYPE_SHADER_MODULE, module, stage ? name_ + " " + stage : name_);
    }
    setLayout_ = createSetLayout(context, bindings_, stages_, name_);
    VkPushConstantRange range{stages_, 0, pushConstantBytes_};
    VkPipelineLayoutCreateInfo layoutInfo{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layoutInfo.setLayoutCount = 1;
    layoutInfo.pSetLayouts = &setLayout_;
    layoutInfo.pushConstantRangeCount = pushConstantBytes_ ? 1 : 0;
    layoutInfo.pPushConstantRanges = &range;
    VK_CHECK(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &pipelineLayout_));
    context.setName(VK_OBJECT_TYPE_PIPELINE_LAYOUT, pipelineLayout_, name_);
  } catch (...) {
    // A constructor that throws runs no destructor: what was made goes now.
    if (setLayout_) vkDestroyDescriptorSetLayout(device, setLayout_, nullptr);
    for (VkShaderModule m : modules_) vkDestroyShaderModule(device, m, nullptr);
    throw;
  }
}

ProgramLayout::~ProgramLayout() {
  VkDevice device = context_->device();
  VkPipelineLayout layout = pipelineLayout_;
  VkDescriptorSetLayout setLayout = setLayout_;
  std::vector<VkShaderModule> modules = modules_;
  context_->retire([=] {
    vkDestroyPipelineLayout(device, layout, nullptr);
    vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
    for (VkShaderModule m : modules) vkDestroyShaderModule(device, m, nullptr);
  });
}

void ProgramLayout::checkPush(const void* push, size_t pushBytes) const {
  if (pushBytes != pushConstantBytes_ && !(pushConstantBytes_ == 0 && push == nullptr)) {
    throw VulkanError("program '" + name_ + "' takes " + std::to_string(pushConstantBytes_) +
                      " bytes of push constants; the call gave " + std::to_string(pushBytes));
  }
}

void ProgramLayout::bind(Commands& commands, VkPipelineBindPoint point, VkPipeline pipeline,
                         std::span<const BufferBinding> resources) const {
  VkDescriptorSet set = writeSet(commands, setLayout_, bindings_, resources, name_);
  vkCmdBindPipeline(commands.handle(), point, pipeline);
  vkCmdBindDescriptorSets(commands.handle(), point, pipelineLayout_, 0, 1, &set, 0, nullptr);
}

void ProgramLayout::push(Commands& commands, const void* data) const {
  if (pushConstantBytes_) vkCmdPushConstants(commands.handle(), pipelineLayout_, stages_, 0, pushConstantBytes_, data);
}

}  // namespace snell::vk
