// A graphics pipeline (vertex + fragment) built from embedded SPIR-V, drawn
// with dynamic rendering. Like ComputeProgram it takes its bindings and push
// constants from reflection; vertices are pulled from storage buffers, so it
// has no vertex input state at all.
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

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace snell::vk {

struct GraphicsProgramDesc {
  std::string name;
  std::span<const uint32_t> vertexSpirv, fragmentSpirv;
  VkFormat colorFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
  VkFormat depthFormat = VK_FORMAT_UNDEFINED;  ///< none: no depth test
  /// Reverse Z: nearer is larger, the depth buffer clears to 0.
  VkCompareOp depthCompare = VK_COMPARE_OP_GREATER;
  bool depthWrite = true;
  /// LINE draws wireframes (needs Context::caps().fillModeNonSolid).
  VkPolygonMode polygonMode = VK_POLYGON_MODE_FILL;
  /// Lines drawn over their own filled faces win the depth test by this much.
  float depthBias = 0.0f;
  /// Source-over blending with the fragment's alpha.
  bool blend = false;
  /// False: a depth-only pass (the colour attachment is left untouched).
  bool colorWrite = true;
};

class GraphicsProgram {
 public:
  GraphicsProgram(Context& context, const GraphicsProgramDesc& desc);
  ~GraphicsProgram();
  GraphicsProgram(const GraphicsProgram&) = delete;
  GraphicsProgram& operator=(const GraphicsProgram&) = delete;

  const std::string& name() const { return name_; }
  /// The driver's statistics of each of its stages (waits for the compile;
  /// empty unless the context captures statistics).
  std::vector<PipelineStatistic> executableStatistics() const;

  /// Binds the pipeline and its resources (one per binding the shaders
  /// declare) inside a rendering scope, with the viewport and scissor covering `area`.
  void bind(Commands& commands, std::span<const BufferBinding> resources, VkRect2D area) const;
  /// Draws `vertexCount` vertices from `firstVertex` as one instance numbered
  /// `instance` (gl_InstanceIndex), after bind().
  template <typename Push>
  void draw(Commands& commands, const Push& push, uint32_t vertexCount, uint32_t firstVertex, uint32_t instance) const {
    record(commands, &push, sizeof(Push), vertexCount, firstVertex, instance);
  }

 private:
  void record(Commands& commands, const void* push, size_t pushBytes, uint32_t vertexCount, uint32_t firstVertex,
              uint32_t instance) const;

  Context* context_;
  std::string name_;
  ProgramLayout layout_;
  std::optional<AsyncPipeline> pipeline_;  ///< after layout_: it goes first, then the modules it reads
};

/// A rendering scope (dynamic rendering) on one colour image and an optional
/// depth image, both in GENERAL layout; the colour cleared when a clear colour
/// is given, the depth cleared or loaded (kept after either). Ends on destruction.
class RenderingScope {
 public:
  RenderingScope(Commands& commands, const Image& color, const Image* depth, VkRect2D area, const float* clearColor,
                 bool clearDepth = true);
  ~RenderingScope();
  RenderingScope(const RenderingScope&) = delete;
  RenderingScope& operator=(const RenderingScope&) = delete;

 private:
  Commands& commands_;
};

}  // namespace snell::vk
