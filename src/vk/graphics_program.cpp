// Graphics pipeline creation from reflected SPIR-V, and checked draws.
#include "vk/graphics_program.h"

#include "vk/error.h"

#include <algorithm>

namespace snell::vk {

namespace {

ShaderReflection reflect(std::span<const uint32_t> spirv, const std::string& name) {
  try {
    return reflectShader(spirv, {}, name);
  } catch (const std::runtime_error& e) {
    throw VulkanError(e.what());
  }
}

VkShaderModule createModule(Context& context, std::span<const uint32_t> spirv, const std::string& name) {
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = spirv.size_bytes();
  info.pCode = spirv.data();
  VkShaderModule module = VK_NULL_HANDLE;
  VK_CHECK(vkCreateShaderModule(context.device(), &info, nullptr, &module));
  context.setName(VK_OBJECT_TYPE_SHADER_MODULE, module, name);
  return module;
}

}  // namespace

GraphicsProgram::GraphicsProgram(Context& context, const GraphicsProgramDesc& desc)
    : context_(&context), name_(desc.name) {
  ShaderReflection vertex = reflect(desc.vertexSpirv, desc.name + " (vertex)");
  ShaderReflection fragment = reflect(desc.fragmentSpirv, desc.name + " (fragment)");
  // Both stages see every binding and the whole push-constant block: one layout, one set.
  bindings_ = vertex.bindings;
  for (const ReflectedBinding& b : fragment.bindings) {
    auto same = std::find_if(bindings_.begin(), bindings_.end(),
                             [&](const ReflectedBinding& o) { return o.set == b.set && o.binding == b.binding; });
    if (same == bindings_.end()) {
      bindings_.push_back(b);
    } else if (same->type != b.type) {
      throw VulkanError("program '" + name_ + "': binding " + std::to_string(b.binding) +
                        " has different types in its vertex and fragment shaders");
    }
  }
  std::sort(bindings_.begin(), bindings_.end(),
            [](const ReflectedBinding& a, const ReflectedBinding& b) { return a.binding < b.binding; });
  pushConstantBytes_ = std::max(vertex.pushConstantBytes, fragment.pushConstantBytes);
  if (pushConstantBytes_ > context.caps().maxPushConstantsSize) {
    throw VulkanError("program '" + name_ + "' has " + std::to_string(pushConstantBytes_) +
                      " bytes of push constants; the device allows " + std::to_string(context.caps().maxPushConstantsSize));
  }
  if (desc.polygonMode != VK_POLYGON_MODE_FILL && !context.caps().fillModeNonSolid) {
    throw VulkanError("program '" + name_ + "' draws lines, which this device cannot (fillModeNonSolid)");
  }
  if (!context.caps().dynamicRendering) {
    throw VulkanError("program '" + name_ + "' needs dynamic rendering, which this device was created without");
  }

  VkDevice device = context.device();
  const VkShaderStageFlags stages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  vertex_ = createModule(context, desc.vertexSpirv, name_ + " vertex");
  fragment_ = createModule(context, desc.fragmentSpirv, name_ + " fragment");
  setLayout_ = createSetLayout(context, bindings_, stages, name_);
  VkPushConstantRange range{stages, 0, pushConstantBytes_};
  VkPipelineLayoutCreateInfo layoutInfo{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layoutInfo.setLayoutCount = 1;
  layoutInfo.pSetLayouts = &setLayout_;
  layoutInfo.pushConstantRangeCount = pushConstantBytes_ ? 1 : 0;
  layoutInfo.pPushConstantRanges = &range;
  VK_CHECK(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &pipelineLayout_));
  context.setName(VK_OBJECT_TYPE_PIPELINE_LAYOUT, pipelineLayout_, name_);

  // The compile runs on its own thread (Context::compileAsync): the state is built there from copies.
  pending_ = context.compileAsync(name_, [&context, desc, vertex = vertex_, fragment = fragment_,
                                         layout = pipelineLayout_](VkPipeline* pipeline) {
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
  return vkCreateGraphicsPipelines(context.device(), context.pipelineCache(), 1, &info, nullptr, pipeline);
  });
}

VkPipeline GraphicsProgram::pipeline() const {
  if (!pipeline_) pipeline_ = pending_.get();
  return pipeline_;
}

GraphicsProgram::~GraphicsProgram() {
  VkDevice device = context_->device();
  VkPipeline handle = VK_NULL_HANDLE;
  try {
    handle = pipeline();  // a compile still running finishes first: it reads the modules and layout
  } catch (...) {
    // The compile failed: its first use reported it; there is no pipeline to destroy.
  }
  VkPipelineLayout layout = pipelineLayout_;
  VkDescriptorSetLayout setLayout = setLayout_;
  VkShaderModule vertex = vertex_, fragment = fragment_;
  context_->retire([=] {
    if (handle) vkDestroyPipeline(device, handle, nullptr);
    vkDestroyPipelineLayout(device, layout, nullptr);
    vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
    vkDestroyShaderModule(device, vertex, nullptr);
    vkDestroyShaderModule(device, fragment, nullptr);
  });
}

void GraphicsProgram::bind(Commands& commands, std::span<const BufferBinding> resources, VkRect2D area) const {
  VkDescriptorSet set = writeSet(commands, setLayout_, bindings_, resources, name_);
  VkCommandBuffer cmd = commands.handle();
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline());
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelineLayout_, 0, 1, &set, 0, nullptr);
  VkViewport viewport{float(area.offset.x), float(area.offset.y), float(area.extent.width), float(area.extent.height),
                      0.0f, 1.0f};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &area);
}

void GraphicsProgram::record(Commands& commands, const void* push, size_t pushBytes, uint32_t vertexCount,
                             uint32_t firstVertex, uint32_t instance) const {
  if (pushBytes != pushConstantBytes_) {
    throw VulkanError("program '" + name_ + "' takes " + std::to_string(pushConstantBytes_) +
                      " bytes of push constants; the call gave " + std::to_string(pushBytes));
  }
  if (vertexCount == 0) return;
  VkCommandBuffer cmd = commands.handle();
  if (pushConstantBytes_) {
    vkCmdPushConstants(cmd, pipelineLayout_, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                       pushConstantBytes_, push);
  }
  vkCmdDraw(cmd, vertexCount, 1, firstVertex, instance);
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
