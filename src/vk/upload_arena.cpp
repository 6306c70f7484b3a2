// Bump allocation over mapped chunks that double when full.
#include "vk/upload_arena.h"

#include <algorithm>

namespace snell::vk {

UploadArena::UploadArena(Context& context, std::string name, VkDeviceSize initialBytes)
    : context_(context), name_(std::move(name)) {
  chunks_.emplace_back(context_, BufferDesc{std::max<VkDeviceSize>(initialBytes, 256), VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                            MemoryDomain::Upload, name_});
}

void UploadArena::reset() {
  if (chunks_.size() > 1) {
    Buffer largest = std::move(chunks_.back());
    chunks_.clear();
    chunks_.push_back(std::move(largest));
  }
  used_ = 0;
}

void UploadArena::copy(Commands& commands, const void* data, VkDeviceSize bytes, const Buffer& destination,
                       VkDeviceSize offset) {
  if (bytes == 0) return;
  VkDeviceSize at = (used_ + 15) & ~VkDeviceSize(15);
  if (at + bytes > chunks_.back().size()) {
    VkDeviceSize size = std::max(2 * chunks_.back().size(), bytes);
    chunks_.emplace_back(context_, BufferDesc{size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryDomain::Upload, name_});
    at = 0;
  }
  std::memcpy(chunks_.back().mapped().data() + at, data, bytes);
  commands.copyBuffer(chunks_.back(), destination, bytes, at, offset);
  used_ = at + bytes;
}

VkDeviceSize UploadArena::capacity() const {
  VkDeviceSize bytes = 0;
  for (const Buffer& b : chunks_) bytes += b.size();
  return bytes;
}

}  // namespace snell::vk
