// The GPU radix sort equals std::stable_sort, pairs and all, for every size and
// key pattern the issue names, with 32- and 64-bit keys.
#include "gpu_test.h"

#include "render/radix_sort.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/error.h"

#include <algorithm>
#include <numeric>
#include <random>
#include <string>
#include <tuple>
#include <vector>

namespace snell::test {
namespace {

enum class Pattern { Random, Sorted, Reversed, AllEqual, HighBitsOnly, FewDistinct };

const char* patternName(Pattern p) {
  switch (p) {
    case Pattern::Random: return "Random";
    case Pattern::Sorted: return "Sorted";
    case Pattern::Reversed: return "Reversed";
    case Pattern::AllEqual: return "AllEqual";
    case Pattern::HighBitsOnly: return "HighBitsOnly";
    case Pattern::FewDistinct: return "FewDistinct";
  }
  return "?";
}

template <typename Key>
std::vector<Key> makeKeys(size_t n, Pattern pattern, uint64_t seed) {
  std::mt19937_64 random(seed);
  constexpr unsigned kBits = sizeof(Key) * 8;
  std::vector<Key> keys(n);
  for (size_t i = 0; i < n; ++i) {
    switch (pattern) {
      case Pattern::Random: keys[i] = static_cast<Key>(random()); break;
      case Pattern::Sorted:
      case Pattern::Reversed: keys[i] = static_cast<Key>(random()); break;
      case Pattern::AllEqual: keys[i] = static_cast<Key>(0x5A5A5A5A5A5A5A5Aull); break;
      case Pattern::HighBitsOnly: keys[i] = static_cast<Key>(static_cast<Key>(random() & 0xFF) << (kBits - 8)); break;
      case Pattern::FewDistinct: keys[i] = static_cast<Key>((random() % 5) * 0x01010101u); break;
    }
  }
  if (pattern == Pattern::Sorted) std::sort(keys.begin(), keys.end());
  if (pattern == Pattern::Reversed) std::sort(keys.rbegin(), keys.rend());
  return keys;
}

/// Sorts on the GPU by the low `keyBits` bits; returns keys and values.
template <typename Key>
void gpuSort(vk::Context& context, std::vector<Key>& keys, std::vector<uint32_t>& values, uint32_t keyBits,
             render::RadixSortTuning tuning = {}) {
  render::RadixSort sort(context, sizeof(Key) == 8 ? render::KeyWidth::Bits64 : render::KeyWidth::Bits32, tuning);
  const VkBufferUsageFlags usage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  vk::Buffer keyBuffer(context, {keys.size() * sizeof(Key), usage, vk::MemoryDomain::Device, "test keys"});
  vk::Buffer valueBuffer(context, {values.size() * 4, usage, vk::MemoryDomain::Device, "test values"});
  vk::upload(context, keyBuffer, keys.data(), keys.size() * sizeof(Key));
  vk::upload(context, valueBuffer, values.data(), values.size() * 4);
  auto scratch = sort.makeScratch(keys.size());
  vk::Commands commands(context, "test sort");
  commands.begin();
  commands.transferToCompute();
  sort.record(commands, keyBuffer, valueBuffer, keys.size(), scratch, keyBits);
  commands.submitAndWait();
  vk::download(context, keyBuffer, keys.data(), keys.size() * sizeof(Key));
  vk::download(context, valueBuffer, values.data(), values.size() * 4);
}

template <typename Key>
void expectMatchesStableSort(vk::Context& context, std::vector<Key> keys, uint32_t keyBits,
                             render::RadixSortTuning tuning = {}) {
  std::vector<uint32_t> values(keys.size());
  std::iota(values.begin(), values.end(), 0u);
  const Key mask = keyBits >= sizeof(Key) * 8 ? Key(~Key(0)) : Key((Key(1) << keyBits) - 1);
  std::vector<std::pair<Key, uint32_t>> expected(keys.size());
  for (size_t i = 0; i < keys.size(); ++i) expected[i] = {keys[i], values[i]};
  std::stable_sort(expected.begin(), expected.end(),
                   [&](const auto& a, const auto& b) { return (a.first & mask) < (b.first & mask); });
  gpuSort(context, keys, values, keyBits, tuning);
  for (size_t i = 0; i < keys.size(); ++i) {
    ASSERT_EQ(keys[i], expected[i].first) << "first key mismatch at " << i << " of " << keys.size();
    ASSERT_EQ(values[i], expected[i].second) << "first value mismatch (stability) at " << i << " of " << keys.size();
  }
}

using SortCase = std::tuple<uint32_t, Pattern, unsigned>;  // size, pattern, key bits

class RadixSortCase : public GpuTest, public ::testing::WithParamInterface<SortCase> {};

TEST_P(RadixSortCase, MatchesStdStableSort) {
  auto [n, pattern, bits] = GetParam();
  if (bits == 32) {
    expectMatchesStableSort(context(), makeKeys<uint32_t>(n, pattern, n * 7 + 1), 32);
  } else {
    expectMatchesStableSort(context(), makeKeys<uint64_t>(n, pattern, n * 7 + 2), 64);
  }
}

INSTANTIATE_TEST_SUITE_P(
    SizesPatternsWidths, RadixSortCase,
    ::testing::Combine(::testing::Values(0u, 1u, 2u, 7u, 255u, 256u, 257u, 4097u, 100000u, 1000003u),
                       ::testing::Values(Pattern::Random, Pattern::Sorted, Pattern::Reversed, Pattern::AllEqual,
                                         Pattern::HighBitsOnly),
                       ::testing::Values(32u, 64u)),
    [](const auto& info) {
      return "n" + std::to_string(std::get<0>(info.param)) + "_" + patternName(std::get<1>(info.param)) + "_" +
             std::to_string(std::get<2>(info.param)) + "bit";
    });

using RadixSortTest = GpuTest;

TEST_F(RadixSortTest, StableAmongManyEqualKeys) {
  expectMatchesStableSort(context(), makeKeys<uint32_t>(50000, Pattern::FewDistinct, 3), 32);
}

TEST_F(RadixSortTest, SortsByTheLowBitsOnlyAndCarriesTheRest) {
  // 30-bit Morton codes with junk above: three passes, the odd count ends in scratch.
  expectMatchesStableSort(context(), makeKeys<uint32_t>(20000, Pattern::Random, 4), 24);
  expectMatchesStableSort(context(), makeKeys<uint64_t>(20000, Pattern::Random, 5), 40);
}

TEST_F(RadixSortTest, SameInputGivesTheSameOutputBitForBit) {
  std::vector<uint32_t> keysA = makeKeys<uint32_t>(30000, Pattern::FewDistinct, 6), keysB = keysA;
  std::vector<uint32_t> valuesA(keysA.size()), valuesB;
  std::iota(valuesA.begin(), valuesA.end(), 0u);
  valuesB = valuesA;
  gpuSort(context(), keysA, valuesA, 32);
  gpuSort(context(), keysB, valuesB, 32);
  EXPECT_EQ(keysA, keysB);
  EXPECT_EQ(valuesA, valuesB);
}

TEST_F(RadixSortTest, EveryWorkgroupShapeSortsTheSame) {
  // The defaults differ per device (512 x 12 on an H200, 128 x 12 here); other
  // shapes exercise several digits per invocation and ragged last tiles.
  // A shape whose per-subgroup counters pass the device's shared memory is
  // refused, saying so (4-lane subgroups need four times the counters of 16);
  // the smallest always fits.
  int sorted = 0;
  for (auto [workgroup, keysPerThread] : {std::pair{64u, 4u}, {64u, 7u}, {128u, 3u}, {128u, 13u}}) {
    SCOPED_TRACE("workgroup " + std::to_string(workgroup) + " x " + std::to_string(keysPerThread));
    render::RadixSortTuning tuning{workgroup, keysPerThread};
    try {
      render::RadixSort probe(context(), render::KeyWidth::Bits64, tuning);
    } catch (const vk::VulkanError& e) {
      EXPECT_NE(std::string(e.what()).find("does not fit in"), std::string::npos) << e.what();
      EXPECT_NE(workgroup, 64u) << "the smallest shape must fit";
      continue;
    }
    expectMatchesStableSort(context(), makeKeys<uint32_t>(30011, Pattern::FewDistinct, workgroup), 32, tuning);
    expectMatchesStableSort(context(), makeKeys<uint64_t>(30011, Pattern::Random, keysPerThread), 64, tuning);
    ++sorted;
  }
  EXPECT_GE(sorted, 2);
}

TEST_F(RadixSortTest, ZeroKeyBitsIsRefused) {
  render::RadixSort sort(context(), render::KeyWidth::Bits32);
  auto scratch = sort.makeScratch(16);
  vk::Buffer keys(context(), {64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryDomain::Device, "k"});
  vk::Commands commands(context(), "refused");
  commands.begin();
  EXPECT_THROW(sort.record(commands, keys, keys, 16, scratch, 0), vk::VulkanError);
  EXPECT_THROW(sort.record(commands, keys, keys, 16, scratch, 33), vk::VulkanError);
  commands.submitAndWait();
}

TEST_F(RadixSortTest, MoreThanTheDeviceCanHoldIsAClearError) {
  render::RadixSort sort(context(), render::KeyWidth::Bits64);
  try {
    sort.makeScratch(sort.maxCount() + 1);
    FAIL();
  } catch (const vk::VulkanError& e) {
    EXPECT_NE(std::string(e.what()).find("at most"), std::string::npos) << e.what();
  }
}

TEST_F(RadixSortTest, HostConvenienceSortsVectors) {
  std::vector<uint64_t> keys = {5, 3, 5, 1};
  std::vector<uint32_t> values = {0, 1, 2, 3};
  render::sortPairs(context(), keys, values);
  EXPECT_EQ(keys, (std::vector<uint64_t>{1, 3, 5, 5}));
  EXPECT_EQ(values, (std::vector<uint32_t>{3, 1, 0, 2}));
}

}  // namespace
}  // namespace snell::test
