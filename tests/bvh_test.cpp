// The GPU LBVH: every group's tree holds each of its primitives exactly once,
// every box holds what is below it, builds are bit-for-bit repeatable, and a
// refit after the triangles move gives boxes that hold the moved triangles.
#include "gpu_test.h"

#include "ref/sah_bvh.h"
#include "render/bvh.h"
#include "vk/commands.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <set>

namespace snell::test {
namespace {

using render::Bvh;
using render::BvhBuilder;
using render::BvhSnapshot;

struct Soup {
  std::vector<float> positions;
  std::vector<uint32_t> indices;
};

// Small random triangles in clusters, so groups overlap and keys collide.
Soup randomSoup(uint32_t triangles, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> centre(-10.0f, 10.0f), offset(-0.3f, 0.3f);
  Soup s;
  for (uint32_t t = 0; t < triangles; ++t) {
    float c[3] = {centre(rng), centre(rng), centre(rng)};
    if (t % 7 == 0) c[0] = c[1] = c[2] = 1.0f;  // many identical centroids
    for (int v = 0; v < 3; ++v) {
      for (int k = 0; k < 3; ++k) s.positions.push_back(t % 7 == 0 ? c[k] + float(v) * 0.01f : c[k] + offset(rng));
      s.indices.push_back(3 * t + uint32_t(v));
    }
  }
  return s;
}

class BvhTest : public GpuTest {
 protected:
  vk::Buffer upload(const void* data, size_t bytes, const char* name) {
    vk::Buffer b(context(), {std::max<size_t>(bytes, 16),
                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                 VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                             vk::MemoryDomain::Device, name});
    if (bytes) vk::upload(context(), b, data, bytes);
    return b;
  }

  BvhSnapshot build(BvhBuilder& builder, Bvh& bvh, const Soup& soup,
                    uint32_t restructureRounds = render::kDefaultRestructureRounds) {
    positions_ = upload(soup.positions.data(), soup.positions.size() * 4, "positions");
    indices_ = upload(soup.indices.data(), soup.indices.size() * 4, "indices");
    vk::Commands commands(context(), "build");
    commands.begin();
    builder.recordTriangleBoxes(commands, bvh, positions_, indices_, 0, bvh.primitiveCount);
    commands.computeToCompute();
    builder.recordBuild(commands, bvh, restructureRounds);
    commands.submitAndWait();
    return builder.download(bvh);
  }

  // Uploads the soup's moved positions and refits `group`, whose triangles are [first, first + count).
  BvhSnapshot refit(BvhBuilder& builder, Bvh& bvh, const Soup& soup, uint32_t group, uint32_t first, uint32_t count) {
    vk::upload(context(), positions_, soup.positions.data(), soup.positions.size() * 4);
    vk::Commands commands(context(), "refit");
    commands.begin();
    builder.recordTriangleBoxes(commands, bvh, positions_, indices_, first, count);
    commands.computeToCompute();
    builder.recordRefit(commands, bvh, group);
    commands.submitAndWait();
    return builder.download(bvh);
  }

  vk::Buffer positions_, indices_;
};

bool contains(const float* outerLo, const float* outerHi, const float* lo, const float* hi) {
  for (int k = 0; k < 3; ++k) {
    if (lo[k] < outerLo[k] || hi[k] > outerHi[k]) return false;
  }
  return true;
}

// Walks one group's tree; returns its primitives and checks box nesting.
std::multiset<uint32_t> walk(const BvhSnapshot& s, uint32_t group, const Soup& soup) {
  std::multiset<uint32_t> seen;
  uint32_t root = s.groups[group].root;
  if (root == gpu::kBvhNone) return seen;
  if (root & gpu::kBvhLeafBit) return {root & ~gpu::kBvhLeafBit};
  std::vector<uint32_t> stack{root};
  while (!stack.empty()) {
    uint32_t n = stack.back();
    stack.pop_back();
    EXPECT_LT(n, s.nodes.size());
    if (n >= s.nodes.size() || seen.size() > s.nodes.size() + 1) break;
    const gpu::BvhNode& node = s.nodes[n];
    for (int c = 0; c < 2; ++c) {
      const float* lo = &node.box[6 * c];
      const float* hi = &node.box[6 * c + 3];
      uint32_t child = node.child[c];
      if (child & gpu::kBvhLeafBit) {
        uint32_t prim = child & ~gpu::kBvhLeafBit;
        seen.insert(prim);
        float triLo[3], triHi[3];
        for (int k = 0; k < 3; ++k) {
          triLo[k] = triHi[k] = soup.positions[9 * prim + size_t(k)];
          for (int v = 1; v < 3; ++v) {
            triLo[k] = std::min(triLo[k], soup.positions[9 * prim + 3 * size_t(v) + size_t(k)]);
            triHi[k] = std::max(triHi[k], soup.positions[9 * prim + 3 * size_t(v) + size_t(k)]);
          }
        }
        EXPECT_TRUE(contains(lo, hi, triLo, triHi)) << "leaf " << prim;
      } else {
        EXPECT_EQ(s.nodes[child].parent, n);
        const gpu::BvhNode& c2 = s.nodes[child];
        EXPECT_TRUE(contains(lo, hi, &c2.box[0], &c2.box[3]) && contains(lo, hi, &c2.box[6], &c2.box[9]))
            << "node " << child << " pokes out of its parent " << n;
        stack.push_back(child);
      }
    }
  }
  return seen;
}

TEST_F(BvhTest, EveryGroupTreeHoldsEachOfItsTrianglesOnce) {
  std::vector<uint32_t> sizes = {1, 0, 1000, 2, 333, 4097};
  uint32_t total = 0;
  for (uint32_t s : sizes) total += s;
  Soup soup = randomSoup(total, 1);
  BvhBuilder builder(context());
  Bvh bvh = builder.makeBvh(sizes, "test forest");
  BvhSnapshot s = build(builder, bvh, soup);
  uint32_t first = 0;
  for (uint32_t g = 0; g < sizes.size(); ++g) {
    std::multiset<uint32_t> seen = walk(s, g, soup);
    std::multiset<uint32_t> expected;
    for (uint32_t p = first; p < first + sizes[g]; ++p) expected.insert(p);
    EXPECT_EQ(seen, expected) << "group " << g;
    if (sizes[g] == 0) {
      EXPECT_EQ(s.groups[g].root, gpu::kBvhNone);
    }
    first += sizes[g];
  }
}

TEST_F(BvhTest, ASingleTriangleForestIsALeafRoot) {
  Soup soup = randomSoup(1, 2);
  BvhBuilder builder(context());
  Bvh bvh = builder.makeBvh({1}, "one triangle");
  BvhSnapshot s = build(builder, bvh, soup);
  EXPECT_EQ(s.groups[0].root, gpu::kBvhLeafBit | 0u);
  EXPECT_FLOAT_EQ(s.groups[0].boxLo[0], std::min({soup.positions[0], soup.positions[3], soup.positions[6]}));
}

TEST_F(BvhTest, BuildsAreBitForBitRepeatable) {
  Soup soup = randomSoup(20000, 3);
  BvhBuilder builder(context());
  Bvh a = builder.makeBvh({5000, 15000}, "a");
  Bvh b = builder.makeBvh({5000, 15000}, "b");
  BvhSnapshot sa = build(builder, a, soup);
  BvhSnapshot sb = build(builder, b, soup);
  ASSERT_EQ(sa.nodes.size(), sb.nodes.size());
  EXPECT_EQ(std::memcmp(sa.nodes.data(), sb.nodes.data(), sa.nodes.size() * sizeof(gpu::BvhNode)), 0);
  EXPECT_EQ(sa.leafPrims, sb.leafPrims);
}

TEST_F(BvhTest, ARefitHoldsTheMovedTrianglesAndKeepsTheTopology) {
  Soup soup = randomSoup(3000, 4);
  BvhBuilder builder(context());
  Bvh bvh = builder.makeBvh({1000, 2000}, "refit");
  BvhSnapshot before = build(builder, bvh, soup);
  // Move group 1's triangles (primitives 1000..2999) a long way.
  for (size_t i = 9 * 1000; i < soup.positions.size(); ++i) soup.positions[i] = soup.positions[i] * 3.0f + 50.0f;
  BvhSnapshot after = refit(builder, bvh, soup, 1, 1000, 2000);
  EXPECT_EQ(after.leafPrims, before.leafPrims);
  EXPECT_EQ(walk(after, 1, soup).size(), 2000u);  // boxes checked against the moved triangles
  EXPECT_GE(after.groups[1].boxLo[0], 50.0f - 3.0f * 10.3f);
  EXPECT_EQ(walk(after, 0, soup).size(), 1000u);
}

double gpuSah(const BvhSnapshot& s, uint32_t group) {
  BvhSnapshot::TreeBoxes tree = s.treeBoxes(group);
  return ref::sahCost(tree.internal, tree.leaves);
}

// Thin triangles along a few long strands with many nearly equal Morton codes:
// the LBVH splits them by code, far from where the SAH would.
Soup strands(uint32_t triangles) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Soup s;
  for (uint32_t t = 0; t < triangles; ++t) {
    float along = u(rng) * 20.0f, strand = float(t % 5);
    float c[3] = {along, strand * 0.9f + 0.05f * std::sin(along), 0.01f * u(rng)};
    for (int v = 0; v < 3; ++v) {
      for (int k = 0; k < 3; ++k) s.positions.push_back(c[k] + (v == k ? 0.02f : 0.0f));
      s.indices.push_back(3 * t + uint32_t(v));
    }
  }
  return s;
}

// The LBVH alone prices these strands at 5.8 times binned SAH.
TEST_F(BvhTest, TreeletRestructuringBringsTheSahOfStrandsWithin1Point4OfBinnedSah) {
  Soup soup = strands(6000);
  BvhBuilder builder(context());
  Bvh bvh = builder.makeBvh({6000}, "strands");
  double lbvh = gpuSah(build(builder, bvh, soup, 0), 0);
  BvhSnapshot restructured = build(builder, bvh, soup);
  EXPECT_EQ(walk(restructured, 0, soup).size(), 6000u);
  std::vector<ref::Aabb> triangles;
  for (uint32_t t = 0; t < 6000; ++t) {
    ref::Aabb b;
    for (int v = 0; v < 3; ++v) b.extend(glm::dvec3(soup.positions[9 * t + 3 * v], soup.positions[9 * t + 3 * v + 1],
                                                    soup.positions[9 * t + 3 * v + 2]));
    triangles.push_back(b);
  }
  double binned = ref::binnedSahCost(triangles);
  double cost = gpuSah(restructured, 0);
  EXPECT_LT(cost, 0.3 * lbvh) << "LBVH alone: " << lbvh / binned << " of binned SAH";
  EXPECT_LT(cost / binned, 1.4) << "LBVH alone: " << lbvh / binned << " of binned SAH";
}

TEST_F(BvhTest, ARefitAfterRestructuringFindsEveryLeafsNewParent) {
  Soup soup = strands(3000);
  BvhBuilder builder(context());
  Bvh bvh = builder.makeBvh({3000}, "strands");
  build(builder, bvh, soup);
  for (float& p : soup.positions) p = -2.0f * p + 7.0f;
  EXPECT_EQ(walk(refit(builder, bvh, soup, 0, 0, 3000), 0, soup).size(), 3000u);  // every box holds its moved triangles
}

}  // namespace
}  // namespace snell::test
