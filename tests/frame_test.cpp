// The frame owner: a frame costs what changed and what refracts on screen.
// Counters come from the renderer's own FrameStats; pixels from its readback.
#include "golden_support.h"
#include "gpu_test.h"

#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/procedural_eye.h"
#include "scene/view.h"
#include "vk/commands.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

namespace snell::test {
namespace {

using render::FrameRequest;
using render::FrameResult;
using render::FrameStats;
using render::Renderer;
using render::ViewOutput;
using render::ViewPixels;
using render::ViewRequest;

constexpr uint32_t kWidth = 96, kHeight = 72;

scene::Scene smallEye() {
  scene::EyeOptions options;
  options.resolution = 16;
  return scene::makeEye(options);
}

ViewRequest traceView(const scene::View& view) {
  ViewRequest v;
  v.settings = {kWidth, kHeight, view, glm::vec3(scene::kDefaultBackground), gpu::kDefaultMaxInterfaces};
  return v;
}

ViewRequest compositeView(const scene::View& view, bool masked = true) {
  ViewRequest v = traceView(view);
  v.output = ViewOutput::Composite;
  v.masked = masked;
  return v;
}

const FrameResult& frame(Renderer& renderer, const scene::Pose& pose, std::vector<ViewRequest> views) {
  FrameRequest request;
  request.pose = &pose;
  request.views = std::move(views);
  return renderer.wait(renderer.submit(request));
}

// One viewport composite of `s` at `pose` from the scene's own camera: what it did.
FrameStats compositeStats(Renderer& renderer, const scene::Scene& s, const scene::Pose& pose) {
  return frame(renderer, pose, {compositeView(scene::resolveView(s, pose, {}))}).stats;
}

// One view's frame with its pixels read back.
const ViewPixels& readFrame(Renderer& renderer, const scene::Pose& pose, const ViewRequest& view) {
  FrameRequest request;
  request.pose = &pose;
  request.views = {view};
  request.readbacks = {{.view = 0}};
  return renderer.wait(renderer.submit(request)).views.at(0);
}

scene::View lookFrom(const glm::dvec3& eye, const glm::dvec3& target = glm::dvec3(0.0)) {
  scene::ViewRequest request;
  request.lookAt = scene::LookAt{eye, target, {0.0, 1.0, 0.0}};
  request.yfov = 0.5;
  return scene::resolveView(scene::Scene{}, scene::Pose{}, request);
}

// The GPU tests of what a frame runs, skips and reads back.
class Frame : public GpuTest {
 protected:
  scene::Scene s = smallEye();  ///< the scene most tests draw, and its rest pose
  scene::Pose pose = scene::evaluate(s, 0.0);
};

// A request no renderer can draw is refused before any GPU work, saying why.
class FrameRequestCheck : public GpuTest {
 protected:
  scene::Scene eye = scene::makeEye();
  scene::Pose pose = scene::evaluate(eye, 0.0);
  FrameRequest request;
  void SetUp() override {
    GpuTest::SetUp();
    request.pose = &pose;
    request.views.emplace_back();
    request.views[0].settings.width = request.views[0].settings.height = 4;
  }
  std::string refusal() {
    try {
      request.check(context(), pose.items.size());
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  }
};

TEST_F(FrameRequestCheck, AFrameOfTheScenesPoseAndItsViewsPasses) { EXPECT_EQ(refusal(), ""); }

TEST_F(FrameRequestCheck, AFrameWithoutAPoseIsRefused) {
  request.pose = nullptr;
  EXPECT_EQ(refusal(), "renderer: a frame needs a pose");
}

TEST_F(FrameRequestCheck, APoseOfAnotherSceneIsRefusedWithBothCounts) {
  scene::Pose other = pose;
  other.items.pop_back();
  request.pose = &other;
  EXPECT_NE(refusal().find("the pose has " + std::to_string(other.items.size()) + " draw items; it was built for " +
                           std::to_string(pose.items.size())),
            std::string::npos);
}

TEST_F(FrameRequestCheck, ARayListThatDoesNotFillItsViewIsRefused) {
  request.views[0].settings.rays.resize(3);
  EXPECT_EQ(refusal(), "renderer: 3 rays for 16 pixels");
}

TEST_F(FrameRequestCheck, AReadbackOfAViewNotAskedForIsRefused) {
  request.readbacks.push_back({.view = 1});
  EXPECT_EQ(refusal(), "renderer: a readback of view 1 of 1");
}

TEST_F(Frame, AStaticScenesSecondFrameRunsNoDeformRefitOrTopLevelWork) {
  scene::Scene s = smallEye();
  scene::Pose pose = scene::evaluate(s, 0.5);
  Renderer renderer(context(), s, pose);
  scene::View view = scene::resolveView(s, pose, {});
  FrameStats first = frame(renderer, pose, {traceView(view)}).stats;
  EXPECT_EQ(first.itemsDeformed, 5u);
  EXPECT_EQ(first.treesBuilt, 5u);
  EXPECT_EQ(first.topLevelBuilt, 1u);
  FrameStats second = frame(renderer, pose, {traceView(view)}).stats;
  EXPECT_EQ(second.itemsDeformed, 0u);
  EXPECT_EQ(second.itemsDeformSkipped, 5u);
  EXPECT_EQ(second.treesBuilt + second.treesRefit, 0u);
  EXPECT_EQ(second.topLevelBuilt + second.topLevelRefit, 0u);
  EXPECT_EQ(second.viewsSkipped, 1u) << "nothing changed: the view keeps its image";
  EXPECT_EQ(second.dispatches, 0u);
}

TEST_F(Frame, OrbitingTheCameraAloneRunsNoDeformOrRefit) {
  scene::Scene s = smallEye();
  scene::Pose pose = scene::evaluate(s, 0.5);
  Renderer renderer(context(), s, pose);
  frame(renderer, pose, {traceView(lookFrom({0.0, 0.0, 0.1}))});
  for (int step = 1; step <= 8; ++step) {
    double angle = 0.1 * step;
    FrameStats stats = frame(renderer, pose, {traceView(lookFrom({0.1 * std::sin(angle), 0.0, 0.1 * std::cos(angle)}))}).stats;
    EXPECT_EQ(stats.itemsDeformed, 0u) << "step " << step;
    EXPECT_EQ(stats.treesRefit + stats.treesBuilt, 0u) << "step " << step;
    EXPECT_EQ(stats.viewsRendered, 1u);
    // Near the eye the origin follows the camera now and then: only the top level moves.
    if (!stats.rebased) {
      EXPECT_EQ(stats.topLevelRefit + stats.topLevelBuilt, 0u) << "step " << step;
    }
  }
}

TEST_F(Frame, OneMovingCharacterOutOfTenRefitsOnlyItsOwnTrees) {
  scene::EyeOptions options;
  options.resolution = 8;
  options.crowd = 10;
  scene::Scene s = scene::makeEye(options);
  scene::Pose rest = scene::evaluate(s, 0.0);
  Renderer renderer(context(), s, rest);
  scene::View view = scene::resolveView(s, rest, {});
  FrameStats first = frame(renderer, rest, {traceView(view)}).stats;
  EXPECT_EQ(first.treesBuilt, 100u);  // 10 characters, 2 eyes, 5 parts

  scene::Pose later = scene::evaluate(s, 2.5);
  scene::Pose oneMoved = rest;
  size_t moved = 0;
  uint64_t movedTriangles = 0;
  for (size_t i = 0; i < rest.items.size(); ++i) {
    if (s.nodes[size_t(rest.items[i].node)].name.rfind("character_3_", 0) == 0) {
      oneMoved.items[i] = later.items[i];
      movedTriangles += s.shapes[size_t(rest.items[i].shape)].triangleCount();
      ++moved;
    }
  }
  ASSERT_EQ(moved, 10u);
  FrameStats stats = frame(renderer, oneMoved, {traceView(view)}).stats;
  EXPECT_EQ(stats.itemsDeformed, 10u);
  EXPECT_EQ(stats.treesRefit, 10u);
  EXPECT_EQ(stats.treesSkipped, 90u);
  EXPECT_EQ(stats.trianglesRefit, movedTriangles);
  EXPECT_EQ(stats.topLevelRefit, 1u);
}

// The whole update is a fixed number of dispatches, however many shapes move.
TEST_F(Frame, TheUpdateTakesAsManyDispatchesForTenCharactersAsForOne) {
  auto dispatches = [&](uint32_t crowd) {
    scene::EyeOptions options;
    options.resolution = 8;
    options.crowd = crowd;
    scene::Scene s = scene::makeEye(options);
    scene::Pose pose = scene::evaluate(s, 0.0);
    Renderer renderer(context(), s, pose);
    scene::View view = scene::resolveView(s, pose, {});
    frame(renderer, pose, {traceView(view)});
    scene::Pose moved = scene::evaluate(s, 2.5);
    FrameStats stats = frame(renderer, moved, {traceView(view)}).stats;
    EXPECT_GT(stats.itemsDeformed, 0u);
    EXPECT_GT(stats.treesRefit, 0u);
    return stats.dispatches;
  };
  uint32_t one = dispatches(1), ten = dispatches(10);
  std::printf("    dispatches of an animated frame: %u for one character, %u for ten\n", one, ten);
  EXPECT_EQ(one, ten);
}

TEST_F(Frame, AnEyeOffScreenGetsNoTraceDispatch) {
  Renderer renderer(context(), s, pose);
  scene::View away = lookFrom({0.0, 0.0, 0.1}, {0.0, 0.0, 1.0});  // looking away from the eye behind
  FrameStats stats = frame(renderer, pose, {compositeView(away)}).stats;
  EXPECT_EQ(stats.traceDispatches, 0u);
  EXPECT_EQ(stats.pixelsTraced, 0u);
  EXPECT_EQ(renderer.blas(), nullptr) << "no view traced, so no tree was built";
}

// From behind, the cornea hides behind the sclera: the mask is empty and the
// trace's indirect dispatch carries no workgroup.
TEST_F(Frame, AnEyeTurnedAwayTracesNoPixel) {
  Renderer renderer(context(), s, pose);
  FrameStats stats = frame(renderer, pose, {compositeView(lookFrom({0.0, 0.0, -0.1}))}).stats;
  EXPECT_EQ(stats.pixelsTraced, 0u);
  EXPECT_LE(stats.traceDispatches, 1u);
}

TEST_F(Frame, TheMaskedTraceCoversExactlyThePixelsWhoseVisibleFaceIsTransmissive) {
  Renderer renderer(context(), s, pose);
  FrameStats stats = compositeStats(renderer, s, pose);
  std::vector<uint32_t> mask(size_t(kWidth) * kHeight);
  vk::downloadImage(context(), renderer.viewImages(0).mask, mask.data());
  uint64_t transmissive = 0;
  for (uint32_t m : mask) transmissive += m != 0 ? 1 : 0;
  std::printf("    %llu of %u pixels show the cornea's tip; %llu traced\n", static_cast<unsigned long long>(transmissive),
              kWidth * kHeight, static_cast<unsigned long long>(stats.pixelsTraced));
  EXPECT_GT(transmissive, 100u);
  EXPECT_LT(transmissive, uint64_t(kWidth) * kHeight / 2);
  EXPECT_EQ(stats.pixelsTraced, transmissive);
  EXPECT_EQ(stats.traceDispatches, 1u);
}

// Tolerance: 1/255 on 99.9% of pixels. Measured on lavapipe: identical, as
// each traced pixel's ray is the same whether its neighbours are traced or not.
TEST_F(Frame, TheMaskedCompositeMatchesTheFullTraceComposite) {
  scene::Scene s = eyeWith(1.376f);
  scene::Pose pose = scene::evaluate(s, 0.0);
  scene::View view = scene::resolveView(s, pose, {});
  auto composite = [&](bool masked) {
    Renderer renderer(context(), s, pose);
    ViewRequest v = compositeView(view, masked);
    v.settings.width = 192;
    v.settings.height = 144;
    return readFrame(renderer, pose, v).composite;
  };
  std::vector<glm::vec4> masked = composite(true), full = composite(false);
  Comparison result = compare(io::toSrgb8({192, 144, masked}), io::toSrgb8({192, 144, full}));
  std::printf("    masked against full trace: %zu of %zu pixels within 1/255, max %d/255\n", result.withinOne,
              result.pixels, result.maxDifference);
  EXPECT_GE(double(result.withinOne) / double(result.pixels), 0.999) << result.firstMismatches;
}

TEST_F(Frame, AViewportOfASceneWithoutTransmissiveFacesBuildsNoTrees) {
  scene::Scene s = smallEye();
  for (scene::Material& m : s.materials) m.transmission = 0.0f;
  scene::Pose pose = scene::evaluate(s, 0.0);
  Renderer renderer(context(), s, pose);
  FrameStats stats = compositeStats(renderer, s, pose);
  EXPECT_FALSE(renderer.seeThrough());
  EXPECT_EQ(renderer.blas(), nullptr);
  EXPECT_EQ(renderer.builder(), nullptr) << "no tree builder and no trace pipeline were made";
  EXPECT_EQ(stats.treesBuilt, 0u);
  EXPECT_EQ(stats.traceDispatches, 0u);
}

TEST_F(Frame, RefractionOffRunsNoTreeWork) {
  Renderer renderer(context(), s, pose);
  ViewRequest view = compositeView(scene::resolveView(s, pose, {}));
  view.raster.refraction = false;
  frame(renderer, pose, {view});
  FrameStats stats = frame(renderer, scene::evaluate(s, 1.0), {view}).stats;
  EXPECT_EQ(stats.itemsDeformed, 5u) << "the raster pass still draws the moving eye";
  EXPECT_EQ(stats.treesBuilt + stats.treesRefit, 0u);
  EXPECT_EQ(stats.topLevelBuilt + stats.topLevelRefit, 0u);
  EXPECT_EQ(renderer.blas(), nullptr);
}

// Frames in flight each keep their own instances, lights and joints: a frame
// recorded while the one before is still queued draws its own pose.
TEST_F(Frame, TwoFramesInFlightEachDrawTheirOwnPose) {
  scene::Scene s = smallEye();
  scene::Pose a = scene::evaluate(s, 0.3), b = scene::evaluate(s, 2.2);
  scene::View view = scene::resolveView(s, a, {});
  auto alone = [&](const scene::Pose& pose) {
    Renderer renderer(context(), s, pose);
    return readFrame(renderer, pose, traceView(view)).trace;
  };
  std::vector<glm::vec4> wantA = alone(a), wantB = alone(b);
  ASSERT_NE(std::memcmp(wantA.data(), wantB.data(), wantA.size() * sizeof(glm::vec4)), 0) << "the poses look the same";

  Renderer renderer(context(), s, a);
  FrameRequest first, second;
  first.pose = &a;
  second.pose = &b;
  first.views = second.views = {traceView(view)};
  first.readbacks = second.readbacks = {{.view = 0}};
  uint64_t fa = renderer.submit(first);
  uint64_t fb = renderer.submit(second);  // recorded before the first is waited for
  std::vector<glm::vec4> gotA = renderer.wait(fa).views.at(0).trace;
  std::vector<glm::vec4> gotB = renderer.wait(fb).views.at(0).trace;
  EXPECT_EQ(std::memcmp(gotA.data(), wantA.data(), wantA.size() * sizeof(glm::vec4)), 0);
  EXPECT_EQ(std::memcmp(gotB.data(), wantB.data(), wantB.size() * sizeof(glm::vec4)), 0);
}

// A grid of small triangles whose one morph target throws each triangle to a
// random place: refitting the grid's tree for it spoils the tree.
scene::Scene scatteringGrid(uint32_t n) {
  scene::Scene s;
  s.source = "scattering grid";
  scene::Shape shape;
  shape.name = "grid";
  scene::MorphTarget scatter;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (uint32_t y = 0; y < n; ++y) {
    for (uint32_t x = 0; x < n; ++x) {
      float cell = 1.0f / float(n);
      glm::vec3 corner(float(x) * cell - 0.5f, float(y) * cell - 0.5f, 0.0f);
      glm::vec3 d(u(rng), u(rng), u(rng) * 0.5f);
      for (glm::vec3 offset : {glm::vec3(0), glm::vec3(0.8f * cell, 0, 0), glm::vec3(0, 0.8f * cell, 0)}) {
        shape.indices.push_back(static_cast<uint32_t>(shape.positions.size()));
        shape.positions.push_back(corner + offset);
        shape.normals.push_back({0, 0, 1});
        scatter.positions.push_back(d - corner);
      }
    }
  }
  shape.targets.push_back(scatter);
  shape.mesh = 0;
  s.shapes.push_back(shape);
  s.meshes.push_back({"grid", {0}, {0.0f}});
  scene::Node node;
  node.name = "grid";
  node.mesh = 0;
  s.nodes.push_back(node);
  s.roots.push_back(0);
  return s;
}

TEST_F(Frame, ARebuildTriggeredBySahGrowthRestoresTheSahRatio) {
  scene::Scene s = scatteringGrid(24);
  scene::Pose flat = scene::evaluate(s, 0.0);
  scene::Pose scattered = flat;
  scattered.items[0].weights = {1.0f};
  ViewRequest view = traceView(lookFrom({0.0, 0.0, 4.0}));
  Renderer renderer(context(), s, flat);
  EXPECT_EQ(frame(renderer, flat, {view}).stats.treesBuilt, 1u);
  FrameStats refit = frame(renderer, scattered, {view}).stats;
  EXPECT_EQ(refit.treesRefit, 1u);
  std::printf("    the refitted tree costs %.2f times its build\n", refit.sahGrowth);
  EXPECT_GT(refit.sahGrowth, 1.5);
  // The next frame rebuilds it, though nothing moved since.
  FrameStats rebuilt = frame(renderer, scattered, {view}).stats;
  EXPECT_EQ(rebuilt.treesBuilt, 1u);
  // Then a small move refits the new tree, priced against its own build.
  scene::Pose nudged = scattered;
  nudged.items[0].weights = {0.999f};
  FrameStats after = frame(renderer, nudged, {view}).stats;
  EXPECT_EQ(after.treesRefit, 1u);
  EXPECT_LT(after.sahGrowth, 1.05);
  EXPECT_EQ(after.treesBuilt, 0u);
}

}  // namespace
}  // namespace snell::test
