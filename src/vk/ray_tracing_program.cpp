#include "vk/ray_tracing_program.h"

#include "vk/error.h"

#include <cstring>

namespace snell::vk {

namespace {

constexpr VkShaderStageFlags kStages =
    VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_MISS_BIT_KHR | VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR;

VkDeviceSize alignUp(VkDeviceSize value, VkDeviceSize alignment) { return (value + alignment - 1) / alignment * alignment; }

// Only the ray generation shader may bind resources, so its bindings are the program's.
ProgramLayout layoutOf(Context& context, const RayTracingProgramDesc& desc) {
  if (!context.caps().driverRayTracing) {
    throw VulkanError("program '" + desc.name +
                      "': this device offers no ray tracing pipelines (VK_KHR_ray_tracing_pipeline)");
  }
  ShaderReflection raygen = reflectProgramShader(desc.raygen, desc.raygenSpecialization, desc.name);
  for (std::span<const uint32_t> other : {desc.miss, desc.closestHit}) {
    if (!reflectProgramShader(other, {}, desc.name).bindings.empty()) {
      throw VulkanError("program '" + desc.name + "': only the ray generation shader may bind resources");
    }
  }
  const std::span<const uint32_t> spirv[] = {desc.raygen, desc.miss, desc.closestHit};
  const char* const names[] = {"raygen", "miss", "closest hit"};
  return ProgramLayout(context, desc.name, spirv, names, raygen.bindings, kStages, raygen.pushConstantBytes);
}

}  // namespace

RayTracingProgram::RayTracingProgram(Context& context, const RayTracingProgramDesc& desc)
    : context_(&context), name_(desc.name), layout_(layoutOf(context, desc)) {
  VkDevice device = context.device();
  const VkShaderStageFlagBits stages[3] = {VK_SHADER_STAGE_RAYGEN_BIT_KHR, VK_SHADER_STAGE_MISS_BIT_KHR,
                                           VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR};
  Specialization raygenSpecialization(desc.raygenSpecialization);
  VkPipelineShaderStageCreateInfo stageInfo[3];
  VkRayTracingShaderGroupCreateInfoKHR groups[3];
  for (uint32_t i = 0; i < 3; ++i) {
    stageInfo[i] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    stageInfo[i].stage = stages[i];
    stageInfo[i].module = layout_.module(i);
    stageInfo[i].pName = "main";
    stageInfo[i].pSpecializationInfo = i == 0 ? raygenSpecialization.info() : nullptr;
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
  pipelineInfo.layout = layout_.pipelineLayout();
  pipelineInfo.flags = context.caps().pipelineStatistics ? VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR : 0;
  auto create = reinterpret_cast<PFN_vkCreateRayTracingPipelinesKHR>(
      vkGetDeviceProcAddr(device, "vkCreateRayTracingPipelinesKHR"));
  auto handlesOf = reinterpret_cast<PFN_vkGetRayTracingShaderGroupHandlesKHR>(
      vkGetDeviceProcAddr(device, "vkGetRayTracingShaderGroupHandlesKHR"));
  traceRays_ = reinterpret_cast<PFN_vkCmdTraceRaysKHR>(vkGetDeviceProcAddr(device, "vkCmdTraceRaysKHR"));
  if (!create || !handlesOf || !traceRays_) throw VulkanError("program '" + name_ + "': no ray tracing entry points");
  VK_CHECK(context.compile(
      [&] { return create(device, VK_NULL_HANDLE, context.pipelineCache(), 1, &pipelineInfo, nullptr, &pipeline_); }));
  context.setName(VK_OBJECT_TYPE_PIPELINE, pipeline_, name_);
  if (context.compileOnly()) return;  // nothing is traced: no shader binding table

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

std::vector<PipelineStatistic> RayTracingProgram::executableStatistics() const {
  return pipelineStatistics(*context_, pipeline_);
}

RayTracingProgram::~RayTracingProgram() {
  // The pipeline goes first; the layout member retires the modules and layouts after it.
  context_->retire([device = context_->device(), pipeline = pipeline_] { vkDestroyPipeline(device, pipeline, nullptr); });
}

void RayTracingProgram::record(Commands& commands, std::span<const BufferBinding> buffers, const void* push,
                               size_t pushBytes, uint32_t width, uint32_t height) const {
  layout_.checkPush(push, pushBytes);
  layout_.bind(commands, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pipeline_, buffers);
  layout_.push(commands, push);
  VkCommandBuffer cmd = commands.handle();
  commands.noteDispatch();
  traceRays_(cmd, &raygenRegion_, &missRegion_, &hitRegion_, &callableRegion_, width, height, 1);
}

}  // namespace snell::vk
