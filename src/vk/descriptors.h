// Descriptor set 0 of a program, built from its reflected bindings and filled
// per use with buffers and storage images: shared by compute and graphics.
#pragma once

#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/spirv_reflect.h"

#include <vulkan/vulkan.h>

#include <span>
#include <string>

namespace snell::vk {

/// One buffer, or one storage image in GENERAL layout, bound to a slot of set 0.
struct BufferBinding {
  uint32_t slot;
  const Buffer* buffer = nullptr;
  const Image* image = nullptr;
};

/// Set 0's layout for `bindings`, visible to `stages`. Throws naming `program`
/// when a shader uses another set.
VkDescriptorSetLayout createSetLayout(Context& context, std::span<const ReflectedBinding> bindings,
                                      VkShaderStageFlags stages, const std::string& program);

/// A set from `commands` (it lives until they are next begun) pointing every
/// binding at its resource. Resources for slots the program does not use are
/// left out; throws naming `program` when a binding it uses is not given.
VkDescriptorSet writeSet(Commands& commands, VkDescriptorSetLayout layout, std::span<const ReflectedBinding> bindings,
                         std::span<const BufferBinding> resources, const std::string& program);

}  // namespace snell::vk
