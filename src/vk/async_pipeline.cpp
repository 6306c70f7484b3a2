#include "vk/async_pipeline.h"

#include <chrono>
#include <utility>

namespace snell::vk {

AsyncPipeline::AsyncPipeline(Context& context, std::string name, std::function<VkResult(VkPipeline*)> create)
    : context_(&context), pending_(context.compileAsync(std::move(name), std::move(create))) {}

VkPipeline AsyncPipeline::get() const {
  if (!pipeline_) pipeline_ = pending_.get();
  return pipeline_;
}

bool AsyncPipeline::ready() const {
  return pipeline_ || pending_.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

AsyncPipeline::~AsyncPipeline() {
  VkPipeline handle = VK_NULL_HANDLE;
  try {
    handle = get();  // a compile still running finishes first
  } catch (...) {
    // The compile failed: its first use reported it, or nothing used it; there is no pipeline to destroy.
  }
  if (handle) context_->retire([device = context_->device(), handle] { vkDestroyPipeline(device, handle, nullptr); });
}

}  // namespace snell::vk
