// Stable key-value radix sort on the GPU: 32- or 64-bit keys, 32-bit values,
// 8 bits per pass. Each pass counts digits per tile, scans the counts with the
// prefix sum, and scatters. No workgroup waits on another (Vulkan promises no
// forward progress between workgroups), so unlike Onesweep it needs no
// decoupled look-back; it pays one extra read of the keys per pass instead.
#pragma once

#include "render/prefix_sum.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/compute_program.h"
#include "vk/context.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace snell::render {

enum class KeyWidth : uint32_t { Bits32 = 1, Bits64 = 2 };

/// Workgroup shape of the sort; zero fields are chosen from the device limits.
struct RadixSortTuning {
  uint32_t workgroupSize = 0;
  uint32_t keysPerThread = 0;
};

class RadixSort {
 public:
  RadixSort(vk::Context& context, KeyWidth width, RadixSortTuning tuning = {});

  /// The workgroup size and keys per invocation it runs with on a device
  /// (`tuning`'s where set); throws vk::VulkanError where none fits.
  static RadixSortTuning shapeFor(const vk::DeviceCaps& caps, KeyWidth width, RadixSortTuning tuning = {});
  /// Its two pipelines on `context`'s device (histogram, scatter); the scan is PrefixSum's.
  static std::vector<vk::ComputeProgramDesc> programDescs(const vk::Context& context, KeyWidth width,
                                                          RadixSortTuning tuning = {});

  /// Ping-pong buffers, digit histogram and scan scratch for up to `capacity` pairs.
  struct Scratch {
    uint64_t capacity = 0;
    vk::Buffer keys;
    vk::Buffer values;
    vk::Buffer histogram;
    PrefixSum::Scratch scan;
  };
  Scratch makeScratch(uint64_t capacity) const;

  /// Records a stable sort of `count` pairs in place, by the low `keyBits` bits
  /// of each key (higher bits are ignored: Morton codes use fewer than 32 or 64).
  /// The caller makes the input visible to compute before; the output is
  /// visible to compute and transfer after.
  void record(vk::Commands& commands, const vk::Buffer& keys, const vk::Buffer& values, uint64_t count,
              const Scratch& scratch, uint32_t keyBits) const;
  void record(vk::Commands& commands, const vk::Buffer& keys, const vk::Buffer& values, uint64_t count,
              const Scratch& scratch) const {
    record(commands, keys, values, count, scratch, 32u * static_cast<uint32_t>(width_));
  }

  /// Times each step (histogram, scan, scatter) as its own pass; the caller
  /// must then not wrap record() in a pass of its own. For benchmarks.
  void setStepTiming(bool on) { stepTiming_ = on; }

  KeyWidth width() const { return width_; }
  uint32_t tileSize() const { return workgroupSize_ * keysPerThread_; }
  uint32_t workgroupSize() const { return workgroupSize_; }
  uint32_t keysPerThread() const { return keysPerThread_; }
  /// The driver's statistics of each program, where the context captures them.
  std::vector<std::string> statistics() const;
  /// The most pairs this device can sort (its storage-buffer range bounds it).
  uint64_t maxCount() const;

 private:
  vk::Context& context_;
  KeyWidth width_;
  uint32_t workgroupSize_ = 0;
  uint32_t keysPerThread_ = 0;
  bool stepTiming_ = false;
  PrefixSum scan_;
  std::unique_ptr<vk::ComputeProgram> histogram_;
  std::unique_ptr<vk::ComputeProgram> scatter_;
};

/// Sorts host vectors through the GPU: a convenience for tests and tools.
void sortPairs(vk::Context& context, std::vector<uint32_t>& keys, std::vector<uint32_t>& values);
void sortPairs(vk::Context& context, std::vector<uint64_t>& keys, std::vector<uint32_t>& values);

}  // namespace snell::render
