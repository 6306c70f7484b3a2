// Reads what a pipeline needs to know from a shader's SPIR-V: the descriptor
// bindings, the push-constant size and, for compute, the workgroup size
// (after specialization).
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace snell::vk {

struct SpecConstant {
  uint32_t id;
  uint32_t value;
};

struct ReflectedBinding {
  uint32_t set = 0;
  uint32_t binding = 0;
  VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
};

struct ShaderReflection {
  std::array<uint32_t, 3> localSize{1, 1, 1};
  std::vector<ReflectedBinding> bindings;  ///< sorted by (set, binding)
  uint32_t pushConstantBytes = 0;
};

/// Reflects one shader stage's SPIR-V; `specialization` overrides spec-constant
/// defaults so a local_size_x_id workgroup size resolves to what the pipeline
/// will use. Throws std::runtime_error naming `name` on malformed input.
ShaderReflection reflectShader(std::span<const uint32_t> spirv, std::span<const SpecConstant> specialization,
                                const std::string& name);

}  // namespace snell::vk
