// The trace's cost counters (TraceAov, read by `snell bench cost`): what one
// camera ray spends on a scene small enough to count by hand. A quad is two
// triangles whose boxes are both the quad, each its own instance's tree.
#include "gpu_test.h"

#include "render/one_view.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/scene_builder.h"
#include "scene/view.h"

#include <gtest/gtest.h>

#include <vector>

namespace snell::test {
namespace {

constexpr uint32_t kSize = 16;

// Opaque unit quads about the z axis facing +z at the depths given; the middle
// pixel's ray runs down -z from (x, 0.2, 2).
// Every pixel's counters, the view looking down -z from (x, 0.2, 2) over the quads.
std::vector<gpu::TraceAov> pixelsThroughQuadsAt(vk::Context& context, std::initializer_list<float> depths, double x = 0.1) {
  scene::Scene s;
  s.source = "quads one behind another";
  scene::Material grey;
  grey.name = "grey";
  int material = scene::addMaterial(s, grey);
  for (float z : depths) {
    scene::Shape quad;
    quad.name = "quad at z " + std::to_string(z);
    scene::addQuad(quad, {-0.5f, -0.5f, z}, {0.5f, -0.5f, z}, {0.5f, 0.5f, z}, {-0.5f, 0.5f, z});
    quad.material = material;
    scene::addRootShape(s, quad);
  }
  scene::Pose pose = scene::evaluate(s, 0.0);
  scene::ViewRequest request;
  request.lookAt = scene::LookAt{{x, 0.2, 2.0}, {x, 0.2, -10.0}, {0.0, 1.0, 0.0}};
  request.yfov = 0.2;
  render::FrameSettings settings{kSize, kSize, scene::resolveView(s, pose, request), glm::vec3(0.0f), 8};
  render::Renderer renderer(context, s, pose);
  return render::renderFrame(renderer, pose, settings, true).aov;
}

gpu::TraceAov middlePixelThroughQuadsAt(vk::Context& context, std::initializer_list<float> depths, double x = 0.1) {
  return pixelsThroughQuadsAt(context, depths, x).at(size_t(kSize / 2) * kSize + kSize / 2);
}

class TraceCounters : public GpuTest {};

TEST_F(TraceCounters, ARayThroughOneQuadReachesBothLeavesAndEntersEveryChild) {
  gpu::TraceAov a = middlePixelThroughQuadsAt(context(), {0.0f});
  ASSERT_NE(a.instance, gpu::kNoHit);
  EXPECT_EQ(a.segments, 1u);
  EXPECT_EQ(a.leafVisits, 2u) << "both triangles' boxes are the quad's";
  EXPECT_EQ(a.triangleTests, 2u) << "a camera ray skips no face";
  EXPECT_EQ(a.deadVisits, 0u);
  EXPECT_EQ(a.culledVisits, 0u);
}

TEST_F(TraceCounters, AQuadBehindTheHitCostsOneVisitCulledByTheNearestHit) {
  gpu::TraceAov a = middlePixelThroughQuadsAt(context(), {0.0f, -1.0f});
  ASSERT_NE(a.instance, gpu::kNoHit);
  EXPECT_NEAR(a.distance, 2.0f, 0.01f) << "the front quad is hit";
  EXPECT_EQ(a.leafVisits, 2u) << "the quad behind is never reached";
  EXPECT_EQ(a.triangleTests, 2u);
  EXPECT_EQ(a.deadVisits, 1u) << "the hidden quad's root enters neither triangle";
  EXPECT_EQ(a.culledVisits, 1u) << "the ray meets both, beyond the hit";
}

TEST_F(TraceCounters, ARayPastEveryQuadSpendsOneDeadVisitThatNoHitCulled) {
  gpu::TraceAov a = middlePixelThroughQuadsAt(context(), {0.0f, -1.0f}, 3.0);
  EXPECT_EQ(a.instance, gpu::kNoHit);
  EXPECT_EQ(a.nodeVisits, 1u) << "the top level's root, whose instances' boxes it misses";
  EXPECT_EQ(a.deadVisits, 1u);
  EXPECT_EQ(a.culledVisits, 0u);
  EXPECT_EQ(a.leafVisits, 0u);
}

TEST_F(TraceCounters, LanesThatReachTheirLeavesTogetherTestThemInOnePassEach) {
  // The quad fills the view: every ray reaches its two triangles at once.
  std::vector<gpu::TraceAov> aov = pixelsThroughQuadsAt(context(), {0.0f});
  uint32_t subgroupSize = aov.front().subgroupSize;
  ASSERT_GT(subgroupSize, 0u);
  uint64_t leafVisits = 0, leafSteps = 0;
  for (const gpu::TraceAov& a : aov) {
    ASSERT_NE(a.instance, gpu::kNoHit);
    ASSERT_EQ(a.leafVisits, 2u);
    leafVisits += a.leafVisits;
    leafSteps += a.leafSteps;
  }
  EXPECT_EQ(leafSteps * subgroupSize, leafVisits) << "every pass of a leaf loop keeps all of a subgroup's lanes at work";
}

}  // namespace
}  // namespace snell::test
