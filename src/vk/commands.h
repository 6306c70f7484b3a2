// Command recording and submission: one command buffer with its fence, the
// descriptor sets its dispatches use, and GPU timestamps per named pass.
#pragma once

#include "vk/buffer.h"
#include "vk/context.h"

#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace snell::vk {

/// GPU time of one named pass of a completed submission.
struct PassTime {
  std::string name;
  double milliseconds = 0;
};

/// An image someone else owns (a host application's), with the layouts it
/// is in before a command writes it and must be in after.
struct ImageTarget {
  VkImage image = VK_NULL_HANDLE;
  uint32_t width = 0, height = 0;
  VkImageLayout layoutBefore = VK_IMAGE_LAYOUT_UNDEFINED, layoutAfter = VK_IMAGE_LAYOUT_GENERAL;
};

/// Records commands, submits them and waits; reusable after wait().
class Commands {
 public:
  Commands(Context& context, std::string name);
  ~Commands();
  Commands(const Commands&) = delete;
  Commands& operator=(const Commands&) = delete;

  /// Starts recording. Waits for a previous submission of this object first.
  void begin();
  /// Ends recording and submits to the context's queue with this object's fence.
  void submit();
  /// The same, waiting for `wait` (if any) at `waitStage` and signalling
  /// `signal` (if any) when done: a swapchain image's acquire and present.
  void submit(VkSemaphore wait, VkPipelineStageFlags waitStage, VkSemaphore signal);
  /// Waits for the submission, then reads back its pass timings.
  void wait();
  /// submit() then wait().
  void submitAndWait();

  VkCommandBuffer handle() const { return buffer_; }
  Context& context() const { return *context_; }

  /// Writes of compute shaders become visible to later compute shaders.
  void computeToCompute();
  /// Transfers (copies, fills) become visible to compute shaders, and compute
  /// reads finish before later transfers overwrite their data.
  void transferToCompute();
  /// Compute writes become visible to transfers (copies to readback buffers).
  void computeToTransfer();
  /// Compute writes become visible to indirect dispatch arguments and to later compute shaders.
  void computeToIndirect();
  /// Depth and colour attachment writes become visible to compute shaders (the mask the trace compacts).
  void graphicsToCompute();
  /// Every earlier command, of this submission or an earlier one, finishes
  /// and its writes are visible before anything later starts: the start of a
  /// frame that rewrites what frames still in flight read.
  void fullBarrier();
  /// Transfer writes become visible to the host after wait().
  void transferToHost();
  /// Compute writes (deformed vertices, the trace image) become visible to the
  /// vertex and fragment shaders of later draws: the one barrier between the
  /// trace and the raster pass.
  void computeToGraphics();
  /// Any other dependency: writes of `srcAccess` at `srcStage` become visible
  /// to `dstAccess` at `dstStage`.
  void barrier(VkPipelineStageFlags srcStage, VkAccessFlags srcAccess, VkPipelineStageFlags dstStage,
               VkAccessFlags dstAccess);
  /// Moves a whole colour image between layouts with a full memory barrier.
  void imageLayout(const Image& image, VkImageLayout from, VkImageLayout to);
  /// Moves an image snell does not own (a swapchain's) between layouts, with
  /// exactly the dependency given.
  void imageBarrier(VkImage image, VkImageAspectFlags aspect, VkImageLayout from, VkImageLayout to,
                    VkPipelineStageFlags srcStage, VkAccessFlags srcAccess, VkPipelineStageFlags dstStage,
                    VkAccessFlags dstAccess);

  void copyBuffer(const Buffer& from, const Buffer& to, VkDeviceSize bytes, VkDeviceSize fromOffset = 0,
                  VkDeviceSize toOffset = 0);
  void fillBuffer(const Buffer& buffer, uint32_t word);
  /// Fills `bytes` (a multiple of 4) from `offset` with `word`.
  void fillBuffer(const Buffer& buffer, uint32_t word, VkDeviceSize offset, VkDeviceSize bytes);
  /// Writes up to 64 KiB of host data into a buffer, in the command stream.
  void updateBuffer(const Buffer& buffer, const void* data, VkDeviceSize bytes, VkDeviceSize offset = 0);
  /// Copies a whole image (GENERAL layout, one mip, one layer) into a buffer, tightly packed.
  void copyImageToBuffer(const Image& image, const Buffer& buffer, VkDeviceSize offset = 0);

  /// Copies a whole colour image (GENERAL) onto another's image of the same
  /// size (a host's), and leaves each as it found it, `target` in its layoutAfter.
  void blitToImage(const Image& image, const ImageTarget& target);

  /// Starts timing a pass once every earlier command has finished; passes do
  /// not nest; at most 128 per submission. No-op where the queue has no timestamps.
  void beginPass(const std::string& name);
  void endPass();
  /// Whether passes are timed at all (on by default): off, beginPass and endPass record nothing.
  void setTimed(bool timed) { timed_ = timed; }
  /// The timings of the last completed submission, in recording order.
  const std::vector<PassTime>& passTimes() const { return times_; }

  /// A descriptor set that lives until this object is next begun.
  VkDescriptorSet allocateSet(VkDescriptorSetLayout layout);
  /// Dispatches and draws recorded since begin() (the frame's counters).
  void noteDispatch() { ++dispatches_; }
  void noteDraw() { ++draws_; }
  uint32_t dispatches() const { return dispatches_; }
  uint32_t draws() const { return draws_; }

  /// Keeps `object` alive until this object is next begun: for resources a
  /// recorded command uses whose owner lets go of them before the submit.
  void keepAlive(std::shared_ptr<void> object) { keptAlive_.push_back(std::move(object)); }

 private:
  void readTimestamps();
  VkDescriptorPool addDescriptorPool();

  Context* context_;
  std::string name_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer buffer_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkQueryPool queries_ = VK_NULL_HANDLE;
  std::vector<VkDescriptorPool> descriptorPools_;
  size_t currentPool_ = 0;
  uint64_t serial_ = 0;  ///< of the submission in flight; 0 when none
  bool recording_ = false;
  uint32_t queryCount_ = 0;
  std::vector<std::string> passNames_;
  bool timed_ = true;
  bool passOpen_ = false;
  std::vector<PassTime> times_;
  std::vector<std::shared_ptr<void>> keptAlive_;
  uint32_t dispatches_ = 0, draws_ = 0;
};

/// Copies bytes into a buffer: directly when it is mapped, else through a staging
/// buffer and a submission that is waited for.
void upload(Context& context, const Buffer& destination, const void* data, VkDeviceSize bytes, VkDeviceSize offset = 0);
/// A storage buffer (storageBuffer) holding `data`.
template <typename T>
Buffer uploadedBuffer(Context& context, const std::vector<T>& data, const std::string& name) {
  Buffer buffer = storageBuffer(context, data.size() * sizeof(T), name);
  if (!data.empty()) upload(context, buffer, data.data(), data.size() * sizeof(T));
  return buffer;
}
/// Copies a buffer's first `bytes` to host memory, through a readback buffer.
void download(Context& context, const Buffer& source, void* data, VkDeviceSize bytes, VkDeviceSize offset = 0);
/// Fills a whole image from tightly packed pixels; leaves it in GENERAL layout.
void uploadImage(Context& context, const Image& image, const void* pixels);
/// Reads a whole image (in GENERAL layout) into tightly packed pixels.
void downloadImage(Context& context, const Image& image, void* pixels);

}  // namespace snell::vk
