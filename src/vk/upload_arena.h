// Host-written data for one frame (instance tables, build and refit lists,
// joint matrices), bump-allocated from mapped buffers and copied to
// device-local ones inside the frame's own commands. Each frame in flight has
// its own arena, so the host never writes what the GPU may still be reading.
#pragma once

#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/context.h"

#include <cstddef>
#include <cstring>
#include <string>
#include <vector>

namespace snell::vk {

class UploadArena {
 public:
  UploadArena(Context& context, std::string name, VkDeviceSize initialBytes = 64 * 1024);

  /// Forgets everything written since the last reset: call only once the
  /// commands that copied from it have completed.
  void reset();

  /// Copies `bytes` into the arena and records their copy to `destination` at `offset`.
  void copy(Commands& commands, const void* data, VkDeviceSize bytes, const Buffer& destination, VkDeviceSize offset = 0);
  template <typename T>
  void copy(Commands& commands, const std::vector<T>& data, const Buffer& destination, VkDeviceSize offset = 0) {
    copy(commands, data.data(), data.size() * sizeof(T), destination, offset);
  }

  /// Bytes of host memory it holds.
  VkDeviceSize capacity() const;

 private:
  Context& context_;
  std::string name_;
  // Chunks are never replaced mid-frame: a copy recorded from one must find it
  // alive when the frame runs. reset() keeps the largest.
  std::vector<Buffer> chunks_;
  VkDeviceSize used_ = 0;
};

}  // namespace snell::vk
