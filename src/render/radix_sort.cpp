// Host side of the radix sort (shaders/comp/sort_histogram.comp, sort_scatter.comp).
#include "render/radix_sort.h"

#include "render/pass_names.h"
#include "shared/radix_sort.h"
#include "vk/error.h"

#include "sort_histogram.spv.h"
#include "sort_scatter.spv.h"

#include <algorithm>

namespace snell::render {

namespace {

uint32_t sharedBytes(uint32_t workgroup, uint32_t keysPerThread, uint32_t minSubgroup, KeyWidth width) {
  uint32_t subgroups = workgroup / minSubgroup;
  uint32_t keyWords = static_cast<uint32_t>(width);
  uint32_t tile = workgroup * keysPerThread;
  return 4 * (subgroups * gpu::kSortRadix       // per-subgroup digit counters
              + 2 * gpu::kSortRadix             // digit starts and shifts
              + tile * keyWords + 1             // staged keys, then values
              + subgroups + 1);                 // the workgroup scan's partial sums
}

}  // namespace

RadixSortTuning RadixSort::shapeFor(const vk::DeviceCaps& caps, KeyWidth width, RadixSortTuning tuning) {
  // Keys per invocation trade registers (occupancy) against tile size (fewer
  // blocks, longer runs per digit when scattering); then the widest workgroup
  // whose shared memory fits. Measured on an H200 at 2^24 pairs: 512 x 12 for
  // 32-bit keys and 384 x 10 for 64-bit keys were the fastest shapes
  // (bench/results/sort-nvidia-h200.md); lavapipe's 32 KiB gives 128 x 12 / 10.
  RadixSortTuning shape;
  shape.keysPerThread = tuning.keysPerThread ? tuning.keysPerThread : (width == KeyWidth::Bits32 ? 12u : 10u);
  shape.workgroupSize = tuning.workgroupSize;
  while (!shape.workgroupSize && shape.keysPerThread > 1) {
    for (uint32_t preferred : {512u, 384u, 256u, 128u, 64u}) {
      if (preferred > caps.maxComputeWorkgroupInvocations || preferred % caps.maxSubgroupSize != 0) continue;
      if (sharedBytes(preferred, shape.keysPerThread, caps.minSubgroupSize, width) <= caps.maxComputeSharedMemoryBytes) {
        shape.workgroupSize = preferred;
        break;
      }
    }
    if (!shape.workgroupSize) shape.keysPerThread = tuning.keysPerThread ? 1 : shape.keysPerThread - 1;
  }
  if (!shape.workgroupSize ||
      sharedBytes(shape.workgroupSize, shape.keysPerThread, caps.minSubgroupSize, width) > caps.maxComputeSharedMemoryBytes) {
    throw vk::VulkanError("the radix sort does not fit in " + std::to_string(caps.maxComputeSharedMemoryBytes) +
                          " bytes of shared memory");
  }
  if (uint64_t(shape.workgroupSize) * shape.keysPerThread > 65536) {
    throw vk::VulkanError("radix sort tiles hold at most 65536 keys (ranks are 16-bit); asked for " +
                          std::to_string(shape.workgroupSize) + " x " + std::to_string(shape.keysPerThread));
  }
  return shape;
}

std::vector<vk::ComputeProgramDesc> RadixSort::programDescs(const vk::Context& context, KeyWidth width,
                                                            RadixSortTuning tuning) {
  const vk::DeviceCaps& caps = context.caps();
  RadixSortTuning shape = shapeFor(caps, width, tuning);
  std::vector<vk::SpecConstant> spec = {
      {gpu::kSortSpecWorkgroupSize, shape.workgroupSize},
      {gpu::kSortSpecKeysPerThread, shape.keysPerThread},
      {gpu::kSortSpecMaxSubgroups, shape.workgroupSize / caps.minSubgroupSize},
      {gpu::kSortSpecKeyWords, static_cast<uint32_t>(width)},
  };
  return {vk::ComputeProgramDesc{"sort_histogram", kSpvSortHistogram, spec, true},
          vk::ComputeProgramDesc{"sort_scatter", kSpvSortScatter, spec, true}};
}

RadixSort::RadixSort(vk::Context& context, KeyWidth width, RadixSortTuning tuning)
    : context_(context), width_(width), scan_(context) {
  RadixSortTuning shape = shapeFor(context.caps(), width, tuning);
  workgroupSize_ = shape.workgroupSize;
  keysPerThread_ = shape.keysPerThread;
  std::vector<vk::ComputeProgramDesc> descs = programDescs(context, width, tuning);
  histogram_ = std::make_unique<vk::ComputeProgram>(context, descs[0]);
  scatter_ = std::make_unique<vk::ComputeProgram>(context, descs[1]);
}

std::vector<std::string> RadixSort::statistics() const {
  std::vector<std::string> lines;
  for (const vk::ComputeProgram* program : {histogram_.get(), scatter_.get()}) {
    for (const std::string& line : program->statistics()) lines.push_back(program->name() + ": " + line);
  }
  return lines;
}

uint64_t RadixSort::maxCount() const {
  uint64_t byRange = context_.caps().maxStorageBufferRange / (4ull * static_cast<uint32_t>(width_));
  uint64_t byIndex = UINT32_MAX - tileSize();  // positions are 32-bit, padding included
  return std::min(byRange, byIndex);
}

RadixSort::Scratch RadixSort::makeScratch(uint64_t capacity) const {
  if (capacity > maxCount()) {
    throw vk::VulkanError("cannot sort " + std::to_string(capacity) + " pairs; this device sorts at most " +
                          std::to_string(maxCount()));
  }
  uint64_t blocks = std::max<uint64_t>(1, (capacity + tileSize() - 1) / tileSize());
  uint64_t keyBytes = capacity * 4 * static_cast<uint32_t>(width_);
  Scratch scratch;
  scratch.capacity = capacity;
  scratch.keys = vk::Buffer(context_, {keyBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                       vk::MemoryDomain::Device, "sort keys ping-pong"});
  scratch.values = vk::Buffer(context_, {capacity * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                         vk::MemoryDomain::Device, "sort values ping-pong"});
  scratch.histogram = vk::Buffer(context_, {blocks * gpu::kSortRadix * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                            vk::MemoryDomain::Device, "sort histogram"});
  scratch.scan = scan_.makeScratch(blocks * gpu::kSortRadix);
  return scratch;
}

void RadixSort::record(vk::Commands& commands, const vk::Buffer& keys, const vk::Buffer& values, uint64_t count,
                       const Scratch& scratch, uint32_t keyBits) const {
  uint32_t widthBits = 32u * static_cast<uint32_t>(width_);
  if (keyBits == 0 || keyBits > widthBits) {
    throw vk::VulkanError("radix sort of " + std::to_string(widthBits) + "-bit keys asked to sort by " +
                          std::to_string(keyBits) + " bits");
  }
  if (count > scratch.capacity) {
    throw vk::VulkanError("radix sort of " + std::to_string(count) + " pairs given scratch for " +
                          std::to_string(scratch.capacity));
  }
  uint64_t keyBytes = count * 4 * static_cast<uint32_t>(width_);
  if (keys.size() < keyBytes || values.size() < count * 4) {
    throw vk::VulkanError("radix sort of " + std::to_string(count) + " pairs: '" + keys.name() + "' or '" +
                          values.name() + "' is too small");
  }
  if (count <= 1) return;

  uint32_t blocks = static_cast<uint32_t>((count + tileSize() - 1) / tileSize());
  uint32_t passes = (keyBits + gpu::kSortRadixBits - 1) / gpu::kSortRadixBits;
  const vk::Buffer* keysIn = &keys;
  const vk::Buffer* keysOut = &scratch.keys;
  const vk::Buffer* valuesIn = &values;
  const vk::Buffer* valuesOut = &scratch.values;
  for (uint32_t digit = 0; digit < passes; ++digit) {
    gpu::SortPush push{static_cast<uint32_t>(count), blocks, digit * gpu::kSortRadixBits, 0};
    if (stepTiming_) commands.beginPass(pass::kSortHistogram);
    histogram_->dispatchGroups(commands,
                               {{gpu::kSortBindingKeysIn, keysIn}, {gpu::kSortBindingHistogram, &scratch.histogram}},
                               push, blocks);
    commands.computeToCompute();
    if (stepTiming_) commands.beginPass(pass::kSortScan);
    scan_.record(commands, scratch.histogram, uint64_t(blocks) * gpu::kSortRadix, scratch.scan);
    commands.computeToCompute();
    if (stepTiming_) commands.beginPass(pass::kSortScatter);
    scatter_->dispatchGroups(commands,
                             {{gpu::kSortBindingKeysIn, keysIn},
                              {gpu::kSortBindingKeysOut, keysOut},
                              {gpu::kSortBindingValuesIn, valuesIn},
                              {gpu::kSortBindingValuesOut, valuesOut},
                              {gpu::kSortBindingHistogram, &scratch.histogram}},
                             push, blocks);
    commands.computeToCompute();
    if (stepTiming_) commands.endPass();
    std::swap(keysIn, keysOut);
    std::swap(valuesIn, valuesOut);
  }
  if (passes % 2 == 1) {
    // The result sits in the scratch buffers; bring it home.
    commands.computeToTransfer();
    commands.copyBuffer(scratch.keys, keys, keyBytes);
    commands.copyBuffer(scratch.values, values, count * 4);
    commands.transferToCompute();
  }
}

namespace {

template <typename Key>
void sortHostPairs(vk::Context& context, std::vector<Key>& keys, std::vector<uint32_t>& values) {
  if (keys.size() != values.size()) throw vk::VulkanError("sortPairs: keys and values differ in length");
  if (keys.size() <= 1) return;
  RadixSort sort(context, sizeof(Key) == 8 ? KeyWidth::Bits64 : KeyWidth::Bits32);
  uint64_t count = keys.size();
  const VkBufferUsageFlags usage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  vk::Buffer keyBuffer(context, {count * sizeof(Key), usage, vk::MemoryDomain::Device, "keys"});
  vk::Buffer valueBuffer(context, {count * 4, usage, vk::MemoryDomain::Device, "values"});
  vk::upload(context, keyBuffer, keys.data(), count * sizeof(Key));
  vk::upload(context, valueBuffer, values.data(), count * 4);
  RadixSort::Scratch scratch = sort.makeScratch(count);
  vk::Commands commands(context, "sortPairs");
  commands.begin();
  commands.transferToCompute();
  sort.record(commands, keyBuffer, valueBuffer, count, scratch);
  commands.submitAndWait();
  vk::download(context, keyBuffer, keys.data(), count * sizeof(Key));
  vk::download(context, valueBuffer, values.data(), count * 4);
}

}  // namespace

void sortPairs(vk::Context& context, std::vector<uint32_t>& keys, std::vector<uint32_t>& values) {
  sortHostPairs(context, keys, values);
}

void sortPairs(vk::Context& context, std::vector<uint64_t>& keys, std::vector<uint32_t>& values) {
  sortHostPairs(context, keys, values);
}

}  // namespace snell::render
