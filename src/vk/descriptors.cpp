// Set layouts from reflection, and sets written with checks that name the program.
#include "vk/descriptors.h"

#include "vk/error.h"

#include <algorithm>
#include <vector>

namespace snell::vk {

VkDescriptorSetLayout createSetLayout(Context& context, std::span<const ReflectedBinding> bindings,
                                      VkShaderStageFlags stages, const std::string& program) {
  std::vector<VkDescriptorSetLayoutBinding> layoutBindings;
  for (const ReflectedBinding& b : bindings) {
    if (b.set != 0) {
      throw VulkanError("program '" + program + "' uses descriptor set " + std::to_string(b.set) +
                        "; only set 0 is supported");
    }
    layoutBindings.push_back({b.binding, b.type, 1, stages, nullptr});
  }
  VkDescriptorSetLayoutCreateInfo setInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  setInfo.bindingCount = static_cast<uint32_t>(layoutBindings.size());
  setInfo.pBindings = layoutBindings.data();
  VkDescriptorSetLayout layout = VK_NULL_HANDLE;
  VK_CHECK(vkCreateDescriptorSetLayout(context.device(), &setInfo, nullptr, &layout));
  context.setName(VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, layout, program);
  return layout;
}

VkDescriptorSet writeSet(Commands& commands, VkDescriptorSetLayout layout, std::span<const ReflectedBinding> bindings,
                         std::span<const BufferBinding> resources, const std::string& program) {
  // Resources may name slots the program does not use (passes share the
  // scene binding set whole); every slot it uses must be given.
  for (const ReflectedBinding& r : bindings) {
    auto given = std::find_if(resources.begin(), resources.end(), [&](const BufferBinding& b) { return b.slot == r.binding; });
    if (given == resources.end()) {
      throw VulkanError("program '" + program + "' uses binding " + std::to_string(r.binding) + "; the call gave none");
    }
  }
  std::vector<VkDescriptorBufferInfo> infos;
  std::vector<VkDescriptorImageInfo> imageInfos;
  std::vector<VkWriteDescriptorSet> writes;
  infos.reserve(resources.size());  // writes point into these: no reallocation
  imageInfos.reserve(resources.size());
  VkDescriptorSet set = commands.allocateSet(layout);
  for (const BufferBinding& b : resources) {
    auto reflected = std::find_if(bindings.begin(), bindings.end(),
                                  [&](const ReflectedBinding& r) { return r.binding == b.slot; });
    if (reflected == bindings.end()) continue;
    VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    write.dstSet = set;
    write.dstBinding = b.slot;
    write.descriptorCount = 1;
    write.descriptorType = reflected->type;
    if (reflected->type == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE) {
      if (!b.image || !b.image->view()) {
        throw VulkanError("program '" + program + "': binding " + std::to_string(b.slot) + " needs a storage image");
      }
      imageInfos.push_back({VK_NULL_HANDLE, b.image->view(), VK_IMAGE_LAYOUT_GENERAL});
      write.pImageInfo = &imageInfos.back();
    } else {
      if (!b.buffer || !b.buffer->handle()) {
        throw VulkanError("program '" + program + "': binding " + std::to_string(b.slot) + " has no buffer");
      }
      infos.push_back({b.buffer->handle(), 0, VK_WHOLE_SIZE});
      write.pBufferInfo = &infos.back();
    }
    writes.push_back(write);
  }
  vkUpdateDescriptorSets(commands.context().device(), static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
  return set;
}

}  // namespace snell::vk
