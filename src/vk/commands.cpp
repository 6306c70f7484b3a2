// Command buffers, fences, barriers, timestamps and staging copies.
#include "vk/commands.h"

#include "vk/error.h"

#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace snell::vk {

namespace {

constexpr uint32_t kMaxTimestamps = 256;
constexpr uint32_t kSetsPerPool = 256;
constexpr uint32_t kDescriptorsPerPool = 2048;

}  // namespace

Commands::Commands(Context& context, std::string name) : context_(&context), name_(std::move(name)) {
  VkDevice device = context.device();
  VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  poolInfo.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  poolInfo.queueFamilyIndex = context.queueFamily();
  VK_CHECK(vkCreateCommandPool(device, &poolInfo, nullptr, &pool_));
  context.setName(VK_OBJECT_TYPE_COMMAND_POOL, pool_, name_);

  VkCommandBufferAllocateInfo bufferInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  bufferInfo.commandPool = pool_;
  bufferInfo.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  bufferInfo.commandBufferCount = 1;
  VK_CHECK(vkAllocateCommandBuffers(device, &bufferInfo, &buffer_));
  context.setName(VK_OBJECT_TYPE_COMMAND_BUFFER, buffer_, name_);

  VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VK_CHECK(vkCreateFence(device, &fenceInfo, nullptr, &fence_));
  context.setName(VK_OBJECT_TYPE_FENCE, fence_, name_);

  if (context.caps().timestampValidBits > 0) {
    VkQueryPoolCreateInfo queryInfo{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    queryInfo.queryType = VK_QUERY_TYPE_TIMESTAMP;
    queryInfo.queryCount = kMaxTimestamps;
    VK_CHECK(vkCreateQueryPool(device, &queryInfo, nullptr, &queries_));
    context.setName(VK_OBJECT_TYPE_QUERY_POOL, queries_, name_);
  }
}

Commands::~Commands() {
  VkDevice device = context_->device();
  if (serial_) {
    // Never free what the GPU is still executing; errors are ignored in a destructor.
    vkWaitForFences(device, 1, &fence_, VK_TRUE, std::numeric_limits<uint64_t>::max());
    context_->noteCompleted(serial_);
  }
  for (VkDescriptorPool p : descriptorPools_) vkDestroyDescriptorPool(device, p, nullptr);
  if (queries_) vkDestroyQueryPool(device, queries_, nullptr);
  vkDestroyFence(device, fence_, nullptr);
  vkDestroyCommandPool(device, pool_, nullptr);
}

void Commands::begin() {
  if (serial_) wait();
  if (recording_) throw std::logic_error("Commands '" + name_ + "': begin() while already recording");
  VkDevice device = context_->device();
  keptAlive_.clear();
  VK_CHECK(vkResetCommandPool(device, pool_, 0));
  for (VkDescriptorPool p : descriptorPools_) VK_CHECK(vkResetDescriptorPool(device, p, 0));
  currentPool_ = 0;
  VkCommandBufferBeginInfo info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(buffer_, &info));
  recording_ = true;
  queryCount_ = 0;
  dispatches_ = 0;
  draws_ = 0;
  passNames_.clear();
  passOpen_ = false;
  if (queries_) vkCmdResetQueryPool(buffer_, queries_, 0, kMaxTimestamps);
}

void Commands::submit() { submit(VK_NULL_HANDLE, 0, VK_NULL_HANDLE); }

void Commands::submit(VkSemaphore wait, VkPipelineStageFlags waitStage, VkSemaphore signal) {
  if (!recording_) throw std::logic_error("Commands '" + name_ + "': submit() without begin()");
  if (context_->compileOnly()) throw std::logic_error("Commands '" + name_ + "': a compile-only context runs nothing");
  if (passOpen_) endPass();
  VK_CHECK(vkEndCommandBuffer(buffer_));
  recording_ = false;
  VK_CHECK(vkResetFences(context_->device(), 1, &fence_));
  VkSubmitInfo info{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  info.commandBufferCount = 1;
  info.pCommandBuffers = &buffer_;
  info.waitSemaphoreCount = wait ? 1 : 0;
  info.pWaitSemaphores = &wait;
  info.pWaitDstStageMask = &waitStage;
  info.signalSemaphoreCount = signal ? 1 : 0;
  info.pSignalSemaphores = &signal;
  VK_CHECK(vkQueueSubmit(context_->queue(), 1, &info, fence_));
  serial_ = context_->noteSubmitted();
}

void Commands::wait() {
  if (!serial_) return;
  // Bounded: a device that stops answering is reported, not waited on forever.
  const double seconds = context_->waitTimeoutSeconds();
  const uint64_t timeoutNs = uint64_t(seconds * 1e9);
  VkResult result = callUnlessFaulted("vkWaitForFences", [&] { return vkWaitForFences(context_->device(), 1, &fence_, VK_TRUE, timeoutNs); });
  if (result == VK_TIMEOUT) {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g s", seconds);
    throw VulkanError("Commands '" + name_ + "': " + context_->facts().name + " did not finish within " + limit + " (" +
                          context_->waitTimeoutWhy() + ")",
                      result);
  }
  VK_CHECK(result);
  context_->noteCompleted(serial_);
  serial_ = 0;
  readTimestamps();
}

void Commands::submitAndWait() {
  submit();
  wait();
}

void Commands::barrier(VkPipelineStageFlags srcStage, VkAccessFlags srcAccess, VkPipelineStageFlags dstStage,
                             VkAccessFlags dstAccess) {
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = srcAccess;
  barrier.dstAccessMask = dstAccess;
  vkCmdPipelineBarrier(buffer_, srcStage, dstStage, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

void Commands::computeToCompute() {
  barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

void Commands::transferToCompute() {
  barrier(VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
}

void Commands::computeToTransfer() {
  barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
}

void Commands::computeToIndirect() {
  barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
          VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
          VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

void Commands::graphicsToCompute() {
  barrier(VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
              VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
          VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
}

void Commands::fullBarrier() {
  barrier(VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
          VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
}

void Commands::transferToHost() {
  barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                VK_ACCESS_HOST_READ_BIT);
}

void Commands::computeToGraphics() {
  barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
}

void Commands::imageLayout(const Image& image, VkImageLayout from, VkImageLayout to) {
  imageBarrier(image.handle(), aspectOf(image.format()), from, to, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
               VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
               VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
}

void Commands::imageBarrier(VkImage image, VkImageAspectFlags aspect, VkImageLayout from, VkImageLayout to,
                            VkPipelineStageFlags srcStage, VkAccessFlags srcAccess, VkPipelineStageFlags dstStage,
                            VkAccessFlags dstAccess) {
  VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  barrier.srcAccessMask = srcAccess;
  barrier.dstAccessMask = dstAccess;
  barrier.oldLayout = from;
  barrier.newLayout = to;
  barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = image;
  barrier.subresourceRange = {aspect, 0, 1, 0, 1};
  vkCmdPipelineBarrier(buffer_, srcStage, dstStage, 0, 0, nullptr, 0, nullptr, 1, &barrier);
}

void Commands::copyBuffer(const Buffer& from, const Buffer& to, VkDeviceSize bytes, VkDeviceSize fromOffset,
                          VkDeviceSize toOffset) {
  if (bytes == 0) return;
  if (fromOffset + bytes > from.size() || toOffset + bytes > to.size()) {
    throw std::invalid_argument("copy of " + std::to_string(bytes) + " bytes from '" + from.name() + "' to '" + to.name() +
                      "' runs past the end of a buffer");
  }
  VkBufferCopy region{fromOffset, toOffset, bytes};
  vkCmdCopyBuffer(buffer_, from.handle(), to.handle(), 1, &region);
}

void Commands::fillBuffer(const Buffer& buffer, uint32_t word) {
  if (buffer.size() == 0) return;
  vkCmdFillBuffer(buffer_, buffer.handle(), 0, buffer.size() & ~VkDeviceSize(3), word);
}

void Commands::updateBuffer(const Buffer& buffer, const void* data, VkDeviceSize bytes, VkDeviceSize offset) {
  if (bytes == 0) return;
  if (bytes > 65536 || bytes % 4 || offset % 4 || offset + bytes > buffer.size()) {
    throw std::invalid_argument("update of " + std::to_string(bytes) + " bytes at " + std::to_string(offset) + " of '" +
                      buffer.name() + "' is too large, misaligned or runs past its end");
  }
  vkCmdUpdateBuffer(buffer_, buffer.handle(), offset, bytes, data);
}

void Commands::copyImageToBuffer(const Image& image, const Buffer& buffer, VkDeviceSize offset) {
  VkDeviceSize bytes = VkDeviceSize(image.width()) * image.height() * image.bytesPerPixel();
  if (offset + bytes > buffer.size()) {
    throw std::invalid_argument("copy of image '" + image.name() + "' into '" + buffer.name() + "' runs past the buffer's end");
  }
  VkBufferImageCopy region{};
  region.bufferOffset = offset;
  region.imageSubresource = {aspectOf(image.format()), 0, 0, 1};
  region.imageExtent = {image.width(), image.height(), 1};
  // Through the layout copies are meant for, and back: whatever wrote the image before, reads it after.
  VkImageAspectFlags aspect = aspectOf(image.format());
  imageBarrier(image.handle(), aspect, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
               VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
               VK_ACCESS_TRANSFER_READ_BIT);
  vkCmdCopyImageToBuffer(buffer_, image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer.handle(), 1, &region);
  imageBarrier(image.handle(), aspect, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
               VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
               VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
}

void Commands::blitToImage(const Image& image, const ImageTarget& target) {
  if (target.width != image.width() || target.height != image.height()) {
    throw std::invalid_argument("blit of image '" + image.name() + "' (" + std::to_string(image.width()) + "x" +
                      std::to_string(image.height()) + ") onto a " + std::to_string(target.width) + "x" +
                      std::to_string(target.height) + " image");
  }
  const VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT;
  // Both through the layouts blits are meant for, and back to where they were.
  imageBarrier(image.handle(), aspect, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
               VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
               VK_ACCESS_TRANSFER_READ_BIT);
  imageBarrier(target.image, aspect, target.layoutBefore, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
               VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
  VkImageBlit region{};
  region.srcSubresource = {aspect, 0, 0, 1};
  region.dstSubresource = region.srcSubresource;
  region.srcOffsets[1] = {int32_t(image.width()), int32_t(image.height()), 1};
  region.dstOffsets[1] = region.srcOffsets[1];
  vkCmdBlitImage(buffer_, image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target.image,
                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region, VK_FILTER_NEAREST);
  imageBarrier(image.handle(), aspect, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
               VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
               VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
  imageBarrier(target.image, aspect, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, target.layoutAfter,
               VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
               VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
}

void Commands::fillBuffer(const Buffer& buffer, uint32_t word, VkDeviceSize offset, VkDeviceSize bytes) {
  if (bytes == 0) return;
  if (offset % 4 || bytes % 4 || offset + bytes > buffer.size()) {
    throw std::invalid_argument("fill of " + std::to_string(bytes) + " bytes at " + std::to_string(offset) + " of '" +
                      buffer.name() + "' is misaligned or runs past its end");
  }
  vkCmdFillBuffer(buffer_, buffer.handle(), offset, bytes, word);
}

void Commands::beginPass(const std::string& name) {
  if (passOpen_) endPass();
  if (!timed_ || !queries_ || queryCount_ + 2 > kMaxTimestamps) return;
  // BOTTOM_OF_PIPE waits for every earlier command: a TOP_OF_PIPE stamp would
  // start the clock while earlier copies still run and charge them to this pass.
  vkCmdWriteTimestamp(buffer_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries_, queryCount_++);
  passNames_.push_back(name);
  passOpen_ = true;
}

void Commands::endPass() {
  if (!passOpen_) return;
  vkCmdWriteTimestamp(buffer_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries_, queryCount_++);
  passOpen_ = false;
}

void Commands::readTimestamps() {
  times_.clear();
  if (!queries_ || queryCount_ == 0) return;
  std::vector<uint64_t> ticks(queryCount_);
  VK_CHECK(vkGetQueryPoolResults(context_->device(), queries_, 0, queryCount_, ticks.size() * sizeof(uint64_t),
                                 ticks.data(), sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  uint32_t bits = context_->caps().timestampValidBits;
  uint64_t mask = bits >= 64 ? ~0ull : ((1ull << bits) - 1);
  double period = context_->caps().timestampPeriodNs;
  for (size_t p = 0; p < passNames_.size(); ++p) {
    uint64_t elapsed = ((ticks[2 * p + 1] & mask) - (ticks[2 * p] & mask)) & mask;
    times_.push_back({passNames_[p], static_cast<double>(elapsed) * period * 1e-6});
  }
}

VkDescriptorPool Commands::addDescriptorPool() {
  VkDescriptorPoolSize sizes[] = {
      {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kDescriptorsPerPool},
      {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, kDescriptorsPerPool / 4},
      {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, kDescriptorsPerPool / 4},
      {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, kDescriptorsPerPool / 4},
  };
  VkDescriptorPoolCreateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  info.maxSets = kSetsPerPool;
  info.poolSizeCount = static_cast<uint32_t>(std::size(sizes));
  info.pPoolSizes = sizes;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VK_CHECK(vkCreateDescriptorPool(context_->device(), &info, nullptr, &pool));
  context_->setName(VK_OBJECT_TYPE_DESCRIPTOR_POOL, pool, name_);
  descriptorPools_.push_back(pool);
  return pool;
}

VkDescriptorSet Commands::allocateSet(VkDescriptorSetLayout layout) {
  while (true) {
    if (currentPool_ == descriptorPools_.size()) addDescriptorPool();
    VkDescriptorSetAllocateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    info.descriptorPool = descriptorPools_[currentPool_];
    info.descriptorSetCount = 1;
    info.pSetLayouts = &layout;
    VkDescriptorSet set = VK_NULL_HANDLE;
    VkResult result = vkAllocateDescriptorSets(context_->device(), &info, &set);
    if (result == VK_SUCCESS) return set;
    if (result != VK_ERROR_OUT_OF_POOL_MEMORY && result != VK_ERROR_FRAGMENTED_POOL) VK_CHECK(result);
    ++currentPool_;  // this pool is full: move on to the next, creating it if needed
  }
}

void upload(Context& context, const Buffer& destination, const void* data, VkDeviceSize bytes, VkDeviceSize offset) {
  if (bytes == 0) return;
  if (offset + bytes > destination.size()) {
    throw std::invalid_argument("upload of " + std::to_string(bytes) + " bytes runs past the end of '" + destination.name() + "'");
  }
  if (!destination.mapped().empty()) {
    std::memcpy(destination.mapped().data() + offset, data, bytes);
    return;
  }
  Buffer staging(context, {bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryDomain::Upload, destination.name() + " staging"});
  std::memcpy(staging.mapped().data(), data, bytes);
  Commands commands(context, "upload " + destination.name());
  commands.begin();
  commands.copyBuffer(staging, destination, bytes, 0, offset);
  commands.submitAndWait();
}

void download(Context& context, const Buffer& source, void* data, VkDeviceSize bytes, VkDeviceSize offset) {
  if (bytes == 0) return;
  if (offset + bytes > source.size()) {
    throw std::invalid_argument("download of " + std::to_string(bytes) + " bytes runs past the end of '" + source.name() + "'");
  }
  Buffer readback(context, {bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryDomain::Readback, source.name() + " readback"});
  Commands commands(context, "download " + source.name());
  commands.begin();
  commands.computeToTransfer();
  commands.copyBuffer(source, readback, bytes, offset, 0);
  commands.transferToHost();
  commands.submitAndWait();
  std::memcpy(data, readback.mapped().data(), bytes);
}

namespace {

VkBufferImageCopy wholeImage(const Image& image) {
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {image.width(), image.height(), 1};
  return region;
}

}  // namespace

void uploadImage(Context& context, const Image& image, const void* pixels) {
  VkDeviceSize bytes = VkDeviceSize(image.width()) * image.height() * image.bytesPerPixel();
  Buffer staging(context, {bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryDomain::Upload, image.name() + " staging"});
  std::memcpy(staging.mapped().data(), pixels, bytes);
  Commands commands(context, "upload " + image.name());
  commands.begin();
  commands.imageLayout(image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
  VkBufferImageCopy region = wholeImage(image);
  vkCmdCopyBufferToImage(commands.handle(), staging.handle(), image.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                         &region);
  commands.imageLayout(image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL);
  commands.submitAndWait();
}

void downloadImage(Context& context, const Image& image, void* pixels) {
  VkDeviceSize bytes = VkDeviceSize(image.width()) * image.height() * image.bytesPerPixel();
  Buffer readback(context, {bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryDomain::Readback, image.name() + " readback"});
  Commands commands(context, "download " + image.name());
  commands.begin();
  commands.imageLayout(image, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  VkBufferImageCopy region = wholeImage(image);
  vkCmdCopyImageToBuffer(commands.handle(), image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.handle(), 1,
                         &region);
  commands.imageLayout(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL);
  commands.transferToHost();
  commands.submitAndWait();
  std::memcpy(pixels, readback.mapped().data(), bytes);
}

}  // namespace snell::vk
