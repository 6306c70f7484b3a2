#include "vk/ray_tracing_program.h"

#include "vk/error.h"

#include <cstring>

namespace snell::vk {

namespace {

constexpr VkShaderStageFlags kStages =
    VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_MISS_BIT_KHR | VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR;

VkDeviceSize alignUp(VkDeviceSize value, VkDeviceSize alignment) { return (value + alignment - 1) / alignment * alignment; }

}  // namespace

RayTracingProgram::RayTracingProgram(Context& context, const RayTracingProgramDesc& desc)
    : context_(&context), name_(desc.name) {
  if (!context.caps().driverRayTracing) {
    throw VulkanError("program '" + name_ + "': this device offers no ray tracing pipelines (VK_KHR_ray_tracing_pipeline)");
  }
  try {
    reflection_ = reflectShader(desc.raygen, {}, desc.name);
    for (std::span<const uint32_t> other : {desc.miss, desc.closestHit}) {
      if (!reflectShader(other, {}, desc.name).bindings.empty()) {
        throw std::runtime_error("program '" + name_ + "': only the ray generation shader may bind resources");
      }
    }
  } catch (const std::runtime_error& e) {
    throw VulkanError(e.what());
  }
  VkDevice device = context.device();
  const std::span<const uint32_t> code[3] = {desc.raygen, desc.miss, desc.closestHit};
  for (int i = 0; i < 3; ++i) {
    VkShaderModuleCreateInfo moduleInfo{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    moduleInfo.codeSize = code[i].size_bytes();
    moduleInfo.pCode = code[i].data();
    VK_CHECK(vkCreateShaderModule(device, &moduleInfo, nullptr, &modules_[i]));
  }
  setLayout_ = createSetLayout(context, reflection_.bindings, kStages, name_);
  VkPushConstantRange range{kStages, 0, reflection_.pushConstantBytes};
  VkPipelineLayoutCreateInfo layoutInfo{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layoutInfo.setLayoutCount = 1;
  layoutInfo.pSetLayouts = &setLayout_;
  layoutInfo.pushConstantRangeCount = reflection_.pushConstantBytes ? 1 : 0;
  layoutInfo.pPushConstantRanges = &range;
  VK_CHECK(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &pipelineLayout_));

  const VkShaderStageFlagBits stages[3] = {VK_SHADER_STAGE_RAYGEN_BIT_KHR, VK_SHADER_STAGE_MISS_BIT_KHR,
                                           VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR};
  VkPipelineShaderStageCreateInfo stageInfo[3];
  VkRayTracingShaderGroupCreateInfoKHR groups[3];
  for (uint32_t i = 0; i < 3; ++i) {
    stageInfo[i] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    stageInfo[i].stage = stages[i];
    stageInfo[i].module = modules_[i];
    stageInfo[i].pName = "main";
    groups[i] = {VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
    groups[i].type = i == 2 ? VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR
                            : VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
    groups[i].generalShader = i == 2 ? VK_SHADER_UNUSED_KHR : i;
    groups[i].closestHitShader = i == 2 ? 2u : VK_SHADER_UNUSED_KHR;
    groups[i].anyHitShader = VK_SHADER_UNUSED_KHR;
    groups[i].intersectionShader = VK_SHADER_UNUSED_KHR;
  }
  VkRayTracingPipelineCreateInfoKHR pipelineInfo{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
  pipelineInfo.stageCount = 3;
  pipelineInfo.pStages = stageInfo;
  pipelineInfo.groupCount = 3;
  pipelineInfo.pGroups = groups;
  pipelineInfo.maxPipelineRayRecursionDepth = 1;  // the ray generation shader loops; hits do not recurse
  pipelineInfo.layout = pipelineLayout_;
  auto create = reinterpret_cast<PFN_vkCreateRayTracingPipelinesKHR>(
      vkGetDeviceProcAddr(device, "vkCreateRayTracingPipelinesKHR"));
  auto handlesOf = reinterpret_cast<PFN_vkGetRayTracingShaderGroupHandlesKHR>(
      vkGetDeviceProcAddr(device, "vkGetRayTracingShaderGroupHandlesKHR"));
  traceRays_ = reinterpret_cast<PFN_vkCmdTraceRaysKHR>(vkGetDeviceProcAddr(device, "vkCmdTraceRaysKHR"));
  if (!create || !handlesOf || !traceRays_) throw VulkanError("program '" + name_ + "': no ray tracing entry points");
  VK_CHECK(context.compile(
      [&] { return create(device, VK_NULL_HANDLE, context.pipelineCache(), 1, &pipelineInfo, nullptr, &pipeline_); }));
  context.setName(VK_OBJECT_TYPE_PIPELINE, pipeline_, name_);

  // The shader binding table: one record per group, each region aligned as the device asks.
  VkPhysicalDeviceRayTracingPipelinePropertiesKHR properties{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &properties};
  vkGetPhysicalDeviceProperties2(context.physicalDevice(), &props);
  uint32_t handleSize = properties.shaderGroupHandleSize;
  VkDeviceSize stride = alignUp(handleSize, properties.shaderGroupHandleAlignment);
  VkDeviceSize region = alignUp(stride, properties.shaderGroupBaseAlignment);
  std::vector<uint8_t> handles(size_t(handleSize) * 3);
  VK_CHECK(handlesOf(device, pipeline_, 0, 3, handles.size(), handles.data()));
  table_ = Buffer(context, {3 * region + properties.shaderGroupBaseAlignment,
                            VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                            MemoryDomain::Upload, name_ + " shader binding table", true});
  VkDeviceAddress base = alignUp(table_.address(), properties.shaderGroupBaseAlignment);
  for (uint32_t i = 0; i < 3; ++i) {
    std::memcpy(table_.mapped().data() + (base - table_.address()) + i * region, handles.data() + i * handleSize,
                handleSize);
  }
  raygenRegion_ = {base, region, region};  // the ray generation region's stride must equal its size
  missRegion_ = {base + region, stride, stride};
  hitRegion_ = {base + 2 * region, stride, stride};
}

RayTracingProgram::~RayTracingProgram() {
  VkDevice device = context_->device();
  VkPipeline pipeline = pipeline_;
  VkPipelineLayout layout = pipelineLayout_;
  VkDescriptorSetLayout setLayout = setLayout_;
  VkShaderModule modules[3] = {modules_[0], modules_[1], modules_[2]};
  context_->retire([=] {
    vkDestroyPipeline(device, pipeline, nullptr);
    vkDestroyPipelineLayout(device, layout, nullptr);
    vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
    for (VkShaderModule m : modules) vkDestroyShaderModule(device, m, nullptr);
  });
}

void RayTracingProgram::record(Commands& commands, std::span<const BufferBinding> buffers, const void* push,
                               size_t pushBytes, uint32_t width, uint32_t height) const {
  if (pushBytes != reflection_.pushConstantBytes) {
    throw VulkanError("program '" + name_ + "' takes " + std::to_string(reflection_.pushConstantBytes) +
                      " bytes of push constants; the call gave " + std::to_string(pushBytes));
  }
  VkDescriptorSet set =
      writeSet(commands, setLayout_, reflection_.bindings, buffers, name_);
  VkCommandBuffer cmd = commands.handle();
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pipeline_);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pipelineLayout_, 0, 1, &set, 0, nullptr);
  vkCmdPushConstants(cmd, pipelineLayout_, kStages, 0, reflection_.pushConstantBytes, push);
  commands.noteDispatch();
  traceRays_(cmd, &raygenRegion_, &missRegion_, &hitRegion_, &callableRegion_, width, height, 1);
}

}  // namespace snell::vk
