// The GPU exclusive prefix sum equals std::exclusive_scan at every size the
// issue names, across one, two and three levels of block sums.
#include "gpu_test.h"

#include "render/prefix_sum.h"
#include "vk/buffer.h"
#include "vk/commands.h"

#include <numeric>
#include <random>
#include <vector>

namespace snell::test {
namespace {

std::vector<uint32_t> gpuExclusiveScan(vk::Context& context, const render::PrefixSum& scan, std::vector<uint32_t> data) {
  vk::Buffer buffer(context, {data.size() * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                                   VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                              vk::MemoryDomain::Device, "scan data"});
  vk::upload(context, buffer, data.data(), data.size() * 4);
  auto scratch = scan.makeScratch(data.size());
  vk::Commands commands(context, "scan");
  commands.begin();
  commands.transferToCompute();
  scan.record(commands, buffer, data.size(), scratch);
  commands.submitAndWait();
  vk::download(context, buffer, data.data(), data.size() * 4);
  return data;
}

class PrefixSumSize : public GpuTest, public ::testing::WithParamInterface<uint32_t> {};

TEST_P(PrefixSumSize, MatchesStdExclusiveScan) {
  uint32_t n = GetParam();
  std::mt19937 random(n);
  std::vector<uint32_t> data(n);
  for (uint32_t& v : data) v = static_cast<uint32_t>(random() % 1000);  // sums stay below 2^32
  std::vector<uint32_t> expected(n);
  std::exclusive_scan(data.begin(), data.end(), expected.begin(), 0u);
  render::PrefixSum scan(context());
  std::vector<uint32_t> got = gpuExclusiveScan(context(), scan, data);
  ASSERT_EQ(got.size(), expected.size());
  for (uint32_t i = 0; i < n; ++i) ASSERT_EQ(got[i], expected[i]) << "first mismatch at " << i << " of " << n;
}

INSTANTIATE_TEST_SUITE_P(Sizes, PrefixSumSize,
                         ::testing::Values(0u, 1u, 2u, 7u, 255u, 256u, 257u, 4097u, 100000u, 1000003u),
                         [](const auto& info) { return std::string("n").append(std::to_string(info.param)); });

using PrefixSumTest = GpuTest;

TEST_F(PrefixSumTest, WrapsModulo2To32LikeUint32Arithmetic) {
  std::vector<uint32_t> data(3000, 0x7FFFFFFFu);
  std::vector<uint32_t> expected(data.size());
  std::exclusive_scan(data.begin(), data.end(), expected.begin(), 0u);
  render::PrefixSum scan(context());
  EXPECT_EQ(gpuExclusiveScan(context(), scan, data), expected);
}

TEST_F(PrefixSumTest, ThreeLevelsOfBlockSumsAreExact) {
  render::PrefixSum scan(context());
  uint64_t tile = scan.tileSize();
  uint32_t n = static_cast<uint32_t>(tile * tile + 3);  // needs a second level of partials
  std::vector<uint32_t> data(n, 1u);
  std::vector<uint32_t> got = gpuExclusiveScan(context(), scan, data);
  for (uint32_t i = 0; i < n; ++i) ASSERT_EQ(got[i], i) << "at " << i;
  EXPECT_EQ(scan.makeScratch(n).levels.size(), 2u);
}

}  // namespace
}  // namespace snell::test
