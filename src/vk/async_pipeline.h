// A pipeline compiled on a thread of its own (Context::compileAsync), and
// owned: the first use waits for it, and when it goes it is retired after the
// frames that may still use it. A compile still running then finishes first,
// since it reads its program's shader modules and layout: a program declares
// its AsyncPipeline after them, so it goes before them.
#pragma once

#include "vk/context.h"

#include <vulkan/vulkan.h>

#include <functional>
#include <future>
#include <string>

namespace snell::vk {

class AsyncPipeline {
 public:
  /// Starts the compile; `create` fills in the pipeline (Context::compileAsync).
  AsyncPipeline(Context& context, std::string name, std::function<VkResult(VkPipeline*)> create);
  ~AsyncPipeline();
  AsyncPipeline(const AsyncPipeline&) = delete;
  AsyncPipeline& operator=(const AsyncPipeline&) = delete;

  /// Waits for the compile, and throws what it threw.
  VkPipeline get() const;
  /// The compile has finished (get() would not wait).
  bool ready() const;

 private:
  Context* context_;
  std::shared_future<VkPipeline> pending_;
  mutable VkPipeline pipeline_ = VK_NULL_HANDLE;
};

}  // namespace snell::vk
