// The GPU BVH (H-PLOC forests): every group's tree holds each of its
// primitives exactly once, every box holds what is below it, builds are
// bit-for-bit repeatable and the same batched or one group at a time, and a
// refit after the triangles move gives boxes that hold the moved triangles.
#include "gpu_test.h"

#include "ref/sah_bvh.h"
#include "render/bvh.h"
#include "shared/trace.h"
#include "vk/commands.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <numbers>
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

  // Builds `groups` (every group when empty) of the soup's triangles.
  BvhSnapshot build(BvhBuilder& builder, Bvh& bvh, const Soup& soup, std::vector<uint32_t> groups = {},
                    uint32_t restructureRounds = render::kDefaultRestructureRounds) {
    positions_ = upload(soup.positions.data(), soup.positions.size() * 4, "positions");
    indices_ = upload(soup.indices.data(), soup.indices.size() * 4, "indices");
    vk::UploadArena arena(context(), "test uploads");
    vk::Commands commands(context(), "build");
    commands.begin();
    builder.recordBuild(commands, bvh, {&positions_, &indices_, nullptr, nullptr}, groups, arena, restructureRounds);
    commands.submitAndWait();
    return builder.download(bvh);
  }

  // Uploads the soup's moved positions and refits `groups` (every group when empty).
  BvhSnapshot refit(BvhBuilder& builder, Bvh& bvh, const Soup& soup, std::vector<uint32_t> groups = {}) {
    vk::upload(context(), positions_, soup.positions.data(), soup.positions.size() * 4);
    vk::UploadArena arena(context(), "test uploads");
    vk::Commands commands(context(), "refit");
    commands.begin();
    builder.recordRefit(commands, bvh, {&positions_, &indices_, nullptr, nullptr}, groups, arena);
    commands.submitAndWait();
    return builder.download(bvh);
  }

  vk::Buffer positions_, indices_;
};

render::BoxFloats triangleBox(const Soup& soup, uint32_t prim) {
  render::BoxFloats b;
  for (int k = 0; k < 3; ++k) {
    b[k] = b[3 + k] = soup.positions[9 * prim + size_t(k)];
    for (int v = 1; v < 3; ++v) {
      b[k] = std::min(b[k], soup.positions[9 * prim + 3 * size_t(v) + size_t(k)]);
      b[3 + k] = std::max(b[3 + k], soup.positions[9 * prim + 3 * size_t(v) + size_t(k)]);
    }
  }
  return b;
}

bool contains(const float* outerLo, const float* outerHi, const float* lo, const float* hi) {
  for (int k = 0; k < 3; ++k) {
    if (lo[k] < outerLo[k] || hi[k] > outerHi[k]) return false;
  }
  return true;
}

// Entry i of node slot `node`'s 4-wide record holds `box` (an exact child
// box as kept, the point at +infinity where empty), `ref` and its `parent`.
void expectWideEntry(const BvhSnapshot& s, uint32_t node, int i, const render::BoxFloats& box, uint32_t ref,
                     uint32_t parent) {
  const gpu::BvhWideEntry& e = s.wideRecords.at(4 * size_t(node) + size_t(i));
  bool empty = box[0] == INFINITY;
  render::BoxFloats stored{e.lo[0], e.lo[1], e.lo[2], e.hi[0], e.hi[1], e.hi[2]};
  EXPECT_EQ(stored, box) << "entry " << i << " of node " << node << "'s 4-wide record";
  EXPECT_EQ(e.ref, empty ? gpu::kBvhNone : ref) << "entry " << i << " of node " << node << "'s 4-wide record";
  EXPECT_EQ(e.parent, parent) << "entry " << i << " of node " << node << "'s 4-wide record";
}

// Node slot `node`'s 4-wide record: each child's two children with their
// kept exact boxes, or a leaf child itself and an empty entry.
void expectWideRecord(const BvhSnapshot& s, uint32_t node) {
  const render::BoxFloats none{INFINITY, INFINITY, INFINITY, INFINITY, INFINITY, INFINITY};
  for (int c = 0; c < 2; ++c) {
    uint32_t child = s.nodes[node].child[c];
    if (!(child & gpu::kBvhLeafBit) && child >= s.nodes.size()) continue;  // the walk reports the reference
    if (child & gpu::kBvhLeafBit) {
      expectWideEntry(s, node, 2 * c, s.exactChildBoxes[2 * size_t(node) + size_t(c)], child, gpu::kBvhNone);
      expectWideEntry(s, node, 2 * c + 1, none, gpu::kBvhNone, gpu::kBvhNone);
    } else {
      for (int k = 0; k < 2; ++k) {
        expectWideEntry(s, node, 2 * c + k, s.exactChildBoxes[2 * size_t(child) + size_t(k)], s.nodes[child].child[k],
                        child);
      }
    }
  }
}

// Walks one group's tree; returns its primitives and checks that every box
// as the trace tests it (quantised and rounded outwards in a compact forest)
// holds the exact box of the triangles below it, that kept exact child boxes
// are that box to the bit and 4-wide records hold them, the parent links,
// the refit arrival bits, and that every reference stays inside the group's
// own slots.
std::multiset<uint32_t> walk(const BvhSnapshot& s, uint32_t group, const Soup& soup) {
  std::multiset<uint32_t> seen;
  const gpu::BvhGroup& g = s.groups[group];
  if (g.root == gpu::kBvhNone) return seen;
  size_t visited = 0;
  // The exact box of everything below `ref`, checking as it goes.
  std::function<render::BoxFloats(uint32_t)> subtree = [&](uint32_t ref) -> render::BoxFloats {
    if (ref & gpu::kBvhLeafBit) {
      uint32_t prim = ref & ~gpu::kBvhLeafBit;
      EXPECT_GE(prim, g.first);
      EXPECT_LT(prim, g.first + g.count);
      seen.insert(prim);
      return triangleBox(soup, prim);
    }
    render::BoxFloats box{INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    EXPECT_GE(ref, g.first);
    EXPECT_LT(ref + 1, g.first + g.count);
    if (ref >= s.nodes.size() || ++visited > s.nodes.size()) return box;
    const gpu::BvhNode& node = s.nodes[ref];
    EXPECT_EQ(node.scale & gpu::kBvhArrivalBit, 0u) << "node " << ref << " was left half-refitted";
    if (!s.wideRecords.empty()) expectWideRecord(s, ref);
    for (int c = 0; c < 2; ++c) {
      uint32_t child = node.child[c];
      if (!(child & gpu::kBvhLeafBit)) {
        EXPECT_EQ(s.nodes[child].parent, ref | (c == 1 ? gpu::kBvhParentRight : 0u));
      }
      render::BoxFloats exact = subtree(child), stored = s.storedChildBox(ref, c);
      EXPECT_TRUE(contains(&stored[0], &stored[3], &exact[0], &exact[3])) << "child " << c << " of node " << ref;
      if (!s.exactChildBoxes.empty()) {  // the trace's exact boxes are the subtree's, to the bit
        render::BoxFloats kept = s.exactChildBoxes[2 * size_t(ref) + size_t(c)], expected = exact;
        if (!(exact[0] <= exact[3] && exact[1] <= exact[4] && exact[2] <= exact[5])) expected.fill(INFINITY);  // empty
        EXPECT_EQ(kept, expected) << "exact box of child " << c << " of node " << ref;
      }
      for (int k = 0; k < 3; ++k) {
        box[size_t(k)] = std::min(box[size_t(k)], exact[size_t(k)]);
        box[size_t(k) + 3] = std::max(box[size_t(k) + 3], exact[size_t(k) + 3]);
      }
    }
    return box;
  };
  render::BoxFloats exact = subtree(g.root);
  EXPECT_TRUE(contains(g.boxLo, g.boxHi, &exact[0], &exact[3])) << "group " << group << "'s box";
  if (!(g.root & gpu::kBvhLeafBit)) {
    EXPECT_EQ(s.nodes[g.root].parent, gpu::kBvhNone);
  }
  return seen;
}

// The SAH of the tree's topology, from the triangles' exact boxes (what the build chose).
double gpuSah(const BvhSnapshot& s, uint32_t group, const Soup& soup) {
  BvhSnapshot::TreeBoxes tree = s.exactTreeBoxes(group, [&](uint32_t prim) { return triangleBox(soup, prim); });
  return ref::sahCost(tree.internal, tree.leaves);
}

double binnedSah(const Soup& soup, uint32_t first, uint32_t count) {
  std::vector<ref::Aabb> triangles;
  for (uint32_t t = first; t < first + count; ++t) {
    render::BoxFloats b = triangleBox(soup, t);
    ref::Aabb a;
    a.lo = {b[0], b[1], b[2]};
    a.hi = {b[3], b[4], b[5]};
    triangles.push_back(a);
  }
  return ref::binnedSahCost(triangles);
}

TEST_F(BvhTest, EveryGroupTreeHoldsEachOfItsTrianglesOnce) {
  std::vector<uint32_t> sizes = {1, 0, 1000, 2, 333, 4097};
  uint32_t total = 0;
  for (uint32_t s : sizes) total += s;
  Soup soup = randomSoup(total, 1);
  BvhBuilder builder(context());
  Bvh bvh = builder.makeBvh(sizes, render::BvhLeaves::Triangles, "test forest");
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
  Bvh bvh = builder.makeBvh({1}, render::BvhLeaves::Triangles, "one triangle");
  BvhSnapshot s = build(builder, bvh, soup);
  EXPECT_EQ(s.groups[0].root, gpu::kBvhLeafBit | 0u);
  EXPECT_FLOAT_EQ(s.groups[0].boxLo[0], std::min({soup.positions[0], soup.positions[3], soup.positions[6]}));
}

TEST_F(BvhTest, BuildsAreBitForBitRepeatable) {
  Soup soup = randomSoup(20000, 3);
  BvhBuilder builder(context());
  Bvh a = builder.makeBvh({5000, 15000}, render::BvhLeaves::Triangles, "a");
  Bvh b = builder.makeBvh({5000, 15000}, render::BvhLeaves::Triangles, "b");
  BvhSnapshot sa = build(builder, a, soup);
  BvhSnapshot sb = build(builder, b, soup);
  ASSERT_EQ(sa.nodes.size(), sb.nodes.size());
  EXPECT_EQ(std::memcmp(sa.nodes.data(), sb.nodes.data(), sa.nodes.size() * sizeof(gpu::BvhNode)), 0);
  ASSERT_EQ(sa.wideRecords.size(), 4 * sa.nodes.size());
  EXPECT_EQ(std::memcmp(sa.wideRecords.data(), sb.wideRecords.data(), sa.wideRecords.size() * sizeof(gpu::BvhWideEntry)),
            0);
}

// The issue's own words: batched builds give the same trees as one shape at a time.
TEST_F(BvhTest, ABatchedBuildGivesTheSameTreesAsOneGroupAtATime) {
  std::vector<uint32_t> sizes = {700, 3, 2500, 1, 1200};
  Soup soup = randomSoup(4404, 6);
  BvhBuilder builder(context());
  Bvh batched = builder.makeBvh(sizes, render::BvhLeaves::Triangles, "batched");
  Bvh single = builder.makeBvh(sizes, render::BvhLeaves::Triangles, "one at a time");
  BvhSnapshot together = build(builder, batched, soup);
  BvhSnapshot apart;
  for (uint32_t g = 0; g < sizes.size(); ++g) apart = build(builder, single, soup, {g});
  EXPECT_EQ(std::memcmp(together.nodes.data(), apart.nodes.data(), together.nodes.size() * sizeof(gpu::BvhNode)), 0);
  EXPECT_EQ(std::memcmp(together.groups.data(), apart.groups.data(), together.groups.size() * sizeof(gpu::BvhGroup)), 0);
  EXPECT_EQ(std::memcmp(together.wideRecords.data(), apart.wideRecords.data(),
                        together.wideRecords.size() * sizeof(gpu::BvhWideEntry)),
            0);
}

TEST_F(BvhTest, RebuildingOneGroupLeavesTheOthersUntouched) {
  Soup soup = randomSoup(3000, 7);
  BvhBuilder builder(context());
  Bvh bvh = builder.makeBvh({1000, 2000}, render::BvhLeaves::Triangles, "subset");
  BvhSnapshot before = build(builder, bvh, soup);
  for (size_t i = 9 * 1000; i < soup.positions.size(); ++i) soup.positions[i] = -soup.positions[i] * 2.0f;
  BvhSnapshot after = build(builder, bvh, soup, {1});
  uint32_t group0Slots = before.groups[0].count;
  EXPECT_EQ(std::memcmp(before.nodes.data(), after.nodes.data(), group0Slots * sizeof(gpu::BvhNode)), 0);
  EXPECT_EQ(walk(after, 0, soup).size(), 1000u);
  EXPECT_EQ(walk(after, 1, soup).size(), 2000u);  // boxes checked against the moved triangles
}

TEST_F(BvhTest, ARefitHoldsTheMovedTrianglesAndKeepsTheTopology) {
  Soup soup = randomSoup(3000, 4);
  BvhBuilder builder(context());
  Bvh bvh = builder.makeBvh({1000, 2000}, render::BvhLeaves::Triangles, "refit");
  BvhSnapshot before = build(builder, bvh, soup);
  // Move group 1's triangles (primitives 1000..2999) a long way.
  for (size_t i = 9 * 1000; i < soup.positions.size(); ++i) soup.positions[i] = soup.positions[i] * 3.0f + 50.0f;
  BvhSnapshot after = refit(builder, bvh, soup, {1});
  for (size_t n = 0; n < before.nodes.size(); ++n) {
    EXPECT_EQ(after.nodes[n].child[0], before.nodes[n].child[0]);
    EXPECT_EQ(after.nodes[n].child[1], before.nodes[n].child[1]);
  }
  EXPECT_EQ(walk(after, 1, soup).size(), 2000u);  // boxes checked against the moved triangles
  EXPECT_GE(after.groups[1].boxLo[0], 50.0f - 3.0f * 10.3f);
  EXPECT_EQ(walk(after, 0, soup).size(), 1000u);
  // A second refit finds every arrival bit clear again, and makes the same nodes.
  BvhSnapshot again = refit(builder, bvh, soup, {1});
  EXPECT_EQ(std::memcmp(after.nodes.data(), again.nodes.data(), after.nodes.size() * sizeof(gpu::BvhNode)), 0);
  EXPECT_EQ(walk(again, 1, soup).size(), 2000u);
}

// A compact forest's nodes hold their children's boxes quantised, rounded
// outwards, after a build and after a refit (a forest with exact child boxes
// leaves them unwritten: its trace never decodes them).
TEST_F(BvhTest, ACompactForestsQuantisedBoxesHoldTheTrianglesAfterABuildAndARefit) {
  Soup soup = randomSoup(3000, 9);
  BvhBuilder builder(context());
  Bvh bvh = builder.makeBvh({1000, 2000}, render::BvhLeaves::Triangles, "compact", render::BvhChildBoxes::Quantised);
  BvhSnapshot built = build(builder, bvh, soup);
  ASSERT_TRUE(built.exactChildBoxes.empty());
  ASSERT_TRUE(built.wideRecords.empty()) << "a compact forest keeps no 4-wide records";
  EXPECT_EQ(walk(built, 0, soup).size(), 1000u);
  EXPECT_EQ(walk(built, 1, soup).size(), 2000u);
  for (size_t i = 9 * 1000; i < soup.positions.size(); ++i) soup.positions[i] = soup.positions[i] * 3.0f + 50.0f;
  BvhSnapshot moved = refit(builder, bvh, soup, {1});
  EXPECT_EQ(walk(moved, 1, soup).size(), 2000u);
  EXPECT_EQ(walk(moved, 0, soup).size(), 1000u);
}

// The refit's fixed-point SAH is the same price the host computes from the boxes.
TEST_F(BvhTest, TheRefitPricesEachTreeAsTheHostDoes) {
  Soup soup = randomSoup(5000, 8);
  BvhBuilder builder(context());
  Bvh bvh = builder.makeBvh({2000, 3000}, render::BvhLeaves::Triangles, "priced");
  build(builder, bvh, soup);
  BvhSnapshot s = refit(builder, bvh, soup);
  for (uint32_t g = 0; g < 2; ++g) {
    double host = gpuSah(s, g, soup);
    double gpu = s.sah[g];
    EXPECT_NEAR(gpu / host, 1.0, 1e-3) << "group " << g << ": host " << host << ", refit " << gpu;
  }
}

// Thin triangles along a few long strands with many nearly equal Morton
// codes: a plain LBVH splits them by code, far from where the SAH would (it
// priced them at 5.8 times binned SAH); H-PLOC's clustering does not.
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

TEST_F(BvhTest, HPlocBringsTheSahOfStrandsWithin1Point2OfBinnedSah) {
  Soup soup = strands(6000);
  BvhBuilder builder(context());
  Bvh bvh = builder.makeBvh({6000}, render::BvhLeaves::Triangles, "strands");
  BvhSnapshot s = build(builder, bvh, soup);
  EXPECT_EQ(walk(s, 0, soup).size(), 6000u);
  double ratio = gpuSah(s, 0, soup) / binnedSah(soup, 0, 6000);
  std::printf("    strands: H-PLOC at %.3f of binned SAH\n", ratio);
  EXPECT_LT(ratio, 1.2);
}

TEST_F(BvhTest, TreeletRestructuringAfterHPlocNeverRaisesTheSah) {
  Soup soup = strands(6000);
  BvhBuilder builder(context());
  Bvh bvh = builder.makeBvh({6000}, render::BvhLeaves::Triangles, "strands");
  double plain = gpuSah(build(builder, bvh, soup), 0, soup);
  BvhSnapshot restructured = build(builder, bvh, soup, {}, 3);
  EXPECT_EQ(walk(restructured, 0, soup).size(), 6000u);
  EXPECT_LE(gpuSah(restructured, 0, soup), plain * (1.0 + 1e-5));
}

TEST_F(BvhTest, ARefitAfterRestructuringFindsEveryLeafsNewParent) {
  Soup soup = strands(3000);
  BvhBuilder builder(context());
  Bvh bvh = builder.makeBvh({3000}, render::BvhLeaves::Triangles, "strands");
  build(builder, bvh, soup, {}, 3);
  for (float& p : soup.positions) p = -2.0f * p + 7.0f;
  EXPECT_EQ(walk(refit(builder, bvh, soup), 0, soup).size(), 3000u);  // every box holds its moved triangles
}

// The deepest internal node of one group's tree, its root at depth 0.
uint32_t deepestNode(const BvhSnapshot& s, uint32_t group) {
  uint32_t root = s.groups[group].root, deepest = 0;
  if (root == gpu::kBvhNone || (root & gpu::kBvhLeafBit)) return 0;
  std::vector<std::pair<uint32_t, uint32_t>> stack{{root, 0u}};
  while (!stack.empty()) {
    auto [node, depth] = stack.back();
    stack.pop_back();
    deepest = std::max(deepest, depth);
    for (uint32_t child : s.nodes.at(node).child) {
      if (!(child & gpu::kBvhLeafBit)) stack.push_back({child, depth + 1});
    }
  }
  return deepest;
}

// A latitude-longitude sphere of 2 rows x columns triangles, the bench's glass sphere's shape.
Soup sphere(uint32_t rows, uint32_t columns) {
  Soup s;
  auto point = [&](uint32_t i, uint32_t j) {
    double theta = std::numbers::pi * i / rows, phi = 2.0 * std::numbers::pi * j / columns;
    for (double v : {std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)}) {
      s.positions.push_back(float(v));
    }
    s.indices.push_back(uint32_t(s.indices.size()));
  };
  for (uint32_t i = 0; i < rows; ++i) {
    for (uint32_t j = 0; j < columns; ++j) {
      point(i, j), point(i + 1, j), point(i + 1, j + 1);
      point(i, j), point(i + 1, j + 1), point(i, j + 1);
    }
  }
  return s;
}

// Once the stack runs short, the 4-wide walk pushes at most one entry a
// level of a tree, as the binary walk does (trace.comp, narrowToBinary), so
// a path to a node at depth d needs d entries of the trace's stack beside
// the top level's; a full stack drops entries, and with them hits. The
// deepest trees of a million triangles the tests know, a sphere with its
// poles' slivers and five strands (near-equal Morton codes), leave room for
// a top level 6 deep. (Triangles on one centroid, a seventh of randomSoup's,
// build a chain: a million of those reach depth 244, where either walk drops
// entries of that chain, which all lie on the one spot.)
TEST_F(BvhTest, TheDeepestTreesOfAMillionTrianglesLeaveTheStackRoomForATopLevel) {
  constexpr uint32_t kTopLevel = 6;
  for (auto [name, soup] : {std::pair{"sphere", sphere(500, 1000)}, std::pair{"strands", strands(1000000)}}) {
    uint32_t triangles = uint32_t(soup.indices.size() / 3);
    BvhBuilder builder(context());
    Bvh bvh = builder.makeBvh({triangles}, render::BvhLeaves::Triangles, name);
    uint32_t depth = deepestNode(build(builder, bvh, soup), 0);
    std::printf("    %s: deepest node at %u\n", name, depth);
    EXPECT_LE(depth + kTopLevel, gpu::kTraceStackSize) << name;
  }
}

// 4-wide records take 128 bytes a node in one buffer: a bottom level keeps
// them while they fit the largest storage buffer the device binds (lavapipe's
// 128 MiB: a million triangles), and a larger one keeps the binary walk;
// top levels and compact trees keep none.
TEST_F(BvhTest, ABottomLevelKeepsWideRecordsWhileTheyFitOneBuffer) {
  const uint64_t fit = context().caps().maxStorageBufferRange / (4 * sizeof(gpu::BvhWideEntry));
  EXPECT_TRUE(render::keepsWideRecords(context(), render::BvhLeaves::Triangles, render::BvhChildBoxes::Exact, fit));
  EXPECT_FALSE(render::keepsWideRecords(context(), render::BvhLeaves::Triangles, render::BvhChildBoxes::Exact, fit + 1));
  EXPECT_FALSE(render::keepsWideRecords(context(), render::BvhLeaves::Instances, render::BvhChildBoxes::Exact, 2));
  EXPECT_FALSE(render::keepsWideRecords(context(), render::BvhLeaves::Triangles, render::BvhChildBoxes::Quantised, 2));
}

}  // namespace
}  // namespace snell::test
