// Graphics pipeline creation from reflected SPIR-V, and checked draws.
#include "vk/graphics_program.h"

#include "vk/error.h"

#include <algorithm>

namespace snell::vk {

namespace {

constexpr VkShaderStageFlags kStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

// Both stages see every binding and the whole push-constant block: one layout, one set.
ProgramLayout layoutOf(Context& context, const GraphicsProgramDesc& desc) {
  ShaderReflection vertex = reflectProgramShader(desc.vertexSpirv, {}, desc.name + " (vertex)");
  ShaderReflection fragment = reflectProgramShader(desc.fragmentSpirv, {}, desc.name + " (fragment)");
  std::vector<ReflectedBinding> bindings = vertex.bindings;
  for (const ReflectedBinding& b : fragment.bindings) {
    auto same = std::find_if(bindings.begin(), bindings.end(),
                             [&](const ReflectedBinding& o) { return o.set == b.set && o.binding == b.binding; });
    if (same == bindings.end()) {
      bindings.push_back(b);
    } else if (same->type != b.type) {
      throw VulkanError("program '" + desc.name + "': binding " + std::to_string(b.binding) +
                        " has different types in its vertex and fragment shaders");
    }
  }
  std::sort(bindings.begin(), bindings.end(),
            [](const ReflectedBinding& a, const ReflectedBinding& b) { return a.binding < b.binding; });
  const std::span<const uint32_t> spirv[] = {desc.vertexSpirv, desc.fragmentSpirv};
  const char* const names[] = {"vertex", "fragment"};
  return ProgramLayout(context, desc.name, spirv, names, std::move(bindings), kStages,
                       std::max(vertex.pushConstantBytes, fragment.pushConstantBytes));
}

}  // namespace

GraphicsProgram::GraphicsProgram(Context& context, const GraphicsProgramDesc& desc)
    : context_(&context), name_(desc.name), layout_(layoutOf(context, desc)) {
  if (desc.polygonMode != VK_POLYGON_MODE_FILL && !context.caps().fillModeNonSolid) {
    throw VulkanError("program '" + name_ + "' draws lines, which this device cannot (fillModeNonSolid)");
  }
  if (!context.caps().dynamicRendering) {
    throw VulkanError("program '" + name_ + "' needs dynamic rendering, which this device was created without");
  }

  // The compile runs on its own thread (Context::compileAsync): the state is built there from copies.
  pipeline_.emplace(context, name_, [&context, desc, vertex = layout_.module(0), fragment = layout_.module(1),
                                      layout = layout_.pipelineLayout()](VkPipeline* pipeline) {
    VkPipelineShaderStageCreateInfo shaderStages[2] = {
        {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_VERTEX_BIT, vertex, "main"},
        {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_FRAGMENT_BIT, fragment, "main"}};
    VkPipelineVertexInputStateCreateInfo vertexInput{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    VkPipelineInputAssemblyStateCreateInfo assembly{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    raster.polygonMode = desc.polygonMode;
    raster.cullMode = VK_CULL_MODE_NONE;  // glass is seen from both sides; the trace culls nothing either
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    raster.depthBiasEnable = desc.depthBias != 0.0f;
    raster.depthBiasConstantFactor = desc.depthBias;
    raster.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo multisample{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    VkPipelineDepthStencilStateCreateInfo depth{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    depth.depthTestEnable = desc.depthFormat != VK_FORMAT_UNDEFINED;
    depth.depthWriteEnable = desc.depthFormat != VK_FORMAT_UNDEFINED && desc.depthWrite;
    depth.depthCompareOp = desc.depthCompare;
    VkPipelineColorBlendAttachmentState attachment{};
    attachment.colorWriteMask = desc.colorWrite ? VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                                                     VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT
                                               : 0;
    if (desc.blend) {
      attachment.blendEnable = VK_TRUE;
      attachment.srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA;
      attachment.dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
      attachment.colorBlendOp = VK_BLEND_OP_ADD;
      attachment.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
      attachment.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
      attachment.alphaBlendOp = VK_BLEND_OP_ADD;
    }
    VkPipelineColorBlendStateCreateInfo blend{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    blend.attachmentCount = 1;
    blend.pAttachments = &attachment;
    VkDynamicState dynamicStates[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic.dynamicStateCount = 2;
    dynamic.pDynamicStates = dynamicStates;
    VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
    rendering.colorAttachmentCount = 1;
    rendering.pColorAttachmentFormats = &desc.colorFormat;
    rendering.depthAttachmentFormat = desc.depthFormat;

    VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    info.pNext = &rendering;
    info.stageCount = 2;
    info.pStages = shaderStages;
    info.pVertexInputState = &vertexInput;
    info.pInputAssemblyState = &assembly;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = &depth;
    info.pColorBlendState = &blend;
    info.pDynamicState = &dynamic;
    info.layout = layout;
    info.flags = context.caps().pipelineStatistics ? VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR : 0;
    return vkCreateGraphicsPipelines(context.device(), context.pipelineCache(), 1, &info, nullptr, pipeline);
  });
}

// The pipeline goes first (a compile still running finishes); the layout member retires the modules and layouts after it.
GraphicsProgram::~GraphicsProgram() = default;

std::vector<PipelineStatistic> GraphicsProgram::executableStatistics() const {
  return pipelineStatistics(*context_, pipeline_->get());
}

void GraphicsProgram::bind(Commands& commands, std::span<const BufferBinding> resources, VkRect2D area) const {
  layout_.bind(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_->get(), resources);
  VkViewport viewport{float(area.offset.x), float(area.offset.y), float(area.extent.width), float(area.extent.height),
                      0.0f, 1.0f};
  vkCmdSetViewport(commands.handle(), 0, 1, &viewport);
  vkCmdSetScissor(commands.handle(), 0, 1, &area);
}

void GraphicsProgram::record(Commands& commands, const void* push, size_t pushBytes, uint32_t vertexCount,
                             uint32_t firstVertex, uint32_t instance) const {
  layout_.checkPush(push, pushBytes);
  if (vertexCount == 0) return;
  layout_.push(commands, push);
  vkCmdDraw(commands.handle(), vertexCount, 1, firstVertex, instance);
  commands.noteDraw();
}

RenderingScope::RenderingScope(Commands& commands, const Image& color, const Image* depth, VkRect2D area,
                               const float* clearColor, bool clearDepth)
    : commands_(commands) {
  VkRenderingAttachmentInfo colorAttachment{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  colorAttachment.imageView = color.view();
  colorAttachment.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
  colorAttachment.loadOp = clearColor ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
  colorAttachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  if (clearColor) {
    for (int i = 0; i < 4; ++i) colorAttachment.clearValue.color.float32[i] = clearColor[i];
  }
  VkRenderingAttachmentInfo depthAttachment{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  if (depth) {
    depthAttachment.imageView = depth->view();
    depthAttachment.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
    depthAttachment.loadOp = clearDepth ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
    depthAttachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    depthAttachment.clearValue.depthStencil = {0.0f, 0};  // reverse Z: 0 is infinitely far
  }
  VkRenderingInfo info{VK_STRUCTURE_TYPE_RENDERING_INFO};
  info.renderArea = area;
  info.layerCount = 1;
  info.colorAttachmentCount = 1;
  info.pColorAttachments = &colorAttachment;
  info.pDepthAttachment = depth ? &depthAttachment : nullptr;
  vkCmdBeginRendering(commands.handle(), &info);
}

RenderingScope::~RenderingScope() { vkCmdEndRendering(commands_.handle()); }

}  // namespace snell::vk
