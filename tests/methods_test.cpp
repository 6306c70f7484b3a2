// The ways of drawing refraction (render/method.h): each is a real path
// through the renderer, and each approximation reduces to what it claims to
// approximate where its assumption holds exactly.
#include "command_run.h"
#include "io/json.h"
#include "golden_support.h"
#include "gpu_test.h"

#include "render/method.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/view.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

namespace snell::test {
namespace {

using render::Method;

constexpr uint32_t kWidth = 160, kHeight = 120;

struct Shot {
  io::Rgb8Image image;
  render::FrameStats stats;
  std::vector<std::string> passes;
};

// One frame of `s` at time 0 from its own camera (or `camera`), drawn by `method`.
Shot draw(vk::Context& context, const scene::Scene& s, Method method, float offsetStrength = 0.02f,
          const scene::ViewRequest& camera = {}) {
  scene::Pose pose = scene::evaluate(s, 0.0);
  scene::View view = scene::resolveView(s, pose, camera);
  render::Renderer renderer(context, s, pose);
  render::FrameSettings settings{kWidth, kHeight, view, glm::vec3(scene::kDefaultBackground), gpu::kDefaultMaxInterfaces};
  render::RasterOptions raster;
  raster.offsetStrength = offsetStrength;
  render::FrameRequest request;
  request.pose = &pose;
  request.views.push_back(render::methodView(method, settings, raster));
  request.readbacks.push_back({.view = 0});
  const render::FrameResult& result = renderer.wait(renderer.submit(request));
  const render::ViewPixels& pixels = result.views.at(0);
  Shot shot;
  shot.image = io::toSrgb8({kWidth, kHeight, render::drawsComposite(method) ? pixels.composite : pixels.trace});
  shot.stats = result.stats;
  for (const vk::PassTime& p : result.passes) shot.passes.push_back(p.name);
  return shot;
}

double shareWithinOne(const io::Rgb8Image& got, const io::Rgb8Image& want) {
  Comparison c = compare(got, want);
  return double(c.withinOne) / double(c.pixels);
}

TEST(Methods, EveryMethodHasAUniqueNameThatParsesBack) {
  for (const render::MethodInfo& m : render::methods()) {
    ASSERT_TRUE(render::methodFromName(m.name).has_value()) << m.name;
    EXPECT_EQ(*render::methodFromName(m.name), m.method);
  }
  EXPECT_FALSE(render::methodFromName("raytrace").has_value());
}

// The eye's rays cross one interface, the cornea, before the iris: bending
// only there is the whole physics.
// Pass times of one frame of a method, as the renderer reports them.
std::vector<vk::PassTime> tracePass(render::Method m, double ms) {
  return {{"tlas", 0.01}, {m == render::Method::DriverRt ? "driver trace" : "trace", ms}};
}

TEST(AutoMethod, IsTraceWhereTheDeviceHasNoRayTracingPipelines) {
  render::AutoMethod automatic(false, false);
  EXPECT_TRUE(automatic.decided());
  EXPECT_EQ(automatic.next(), render::Method::Trace);
  EXPECT_NE(automatic.describe().find("no ray tracing pipelines"), std::string::npos) << automatic.describe();
}

TEST(AutoMethod, IsTheMaskedTraceForAViewport) {
  render::AutoMethod automatic(true, true);
  EXPECT_EQ(automatic.next(), render::Method::Masked);
}

TEST(AutoMethod, IsTraceForTooFewFramesToTime) {
  render::AutoMethod automatic(true, false, 3);
  EXPECT_EQ(automatic.next(), render::Method::Trace);
}

TEST(AutoMethod, TimesBothThenKeepsTheFasterWithoutCountingEachOnesFirstFrame) {
  for (double driverMs : {0.5, 2.0}) {
    render::AutoMethod automatic(true, false);
    int frames = 0;
    while (!automatic.decided()) {
      render::Method m = automatic.next();
      // A first frame of either that looks fast must not decide it.
      bool first = frames < 2;
      automatic.note(m, tracePass(m, first ? 0.01 : (m == render::Method::Trace ? 1.0 : driverMs)));
      ASSERT_LT(++frames, 20);
    }
    EXPECT_EQ(frames, 2 * (render::AutoMethod::kTrials + 1));
    EXPECT_EQ(automatic.next(), driverMs < 1.0 ? render::Method::DriverRt : render::Method::Trace) << automatic.describe();
    EXPECT_NE(automatic.describe().find("trace 1.000 ms"), std::string::npos) << automatic.describe();
  }
}

// The GPU tests of the methods' pictures against each other.
class MethodImages : public GpuTest {};

TEST_F(MethodImages, TraceOnceIsTheFullTraceWhereRaysCrossOneInterface) {
  scene::Scene eye = eyeWith(1.376f);
  Comparison c = compare(draw(context(), eye, Method::TraceOnce).image, draw(context(), eye, Method::Trace).image);
  EXPECT_EQ(c.withinOne, c.pixels) << c.firstMismatches;
}

// Through a prism a ray crosses two faces; bending at the first alone must show.
TEST_F(MethodImages, TraceOnceDiffersFromTheFullTraceThroughAPrism) {
  scene::Scene prism = prismScene();
  scene::ViewRequest camera;  // the golden image's view: light reflected inside the prism
  camera.lookAt = scene::LookAt{{0.6, 0.3, -6.0}, {0.6, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  camera.yfov = 0.6;
  EXPECT_LT(shareWithinOne(draw(context(), prism, Method::TraceOnce, 0.02f, camera).image,
                           draw(context(), prism, Method::Trace, 0.02f, camera).image),
            0.95);
}

TEST_F(MethodImages, ScreenSpaceMethodsBuildNoTreeAndDispatchNoTrace) {
  scene::Scene eye = eyeWith(1.376f);
  for (Method m : {Method::IrisPlane, Method::NormalOffset}) {
    Shot shot = draw(context(), eye, m);
    EXPECT_EQ(shot.stats.treesBuilt, 0u) << render::methodName(m);
    EXPECT_EQ(shot.stats.traceDispatches, 0u) << render::methodName(m);
    EXPECT_NE(std::find(shot.passes.begin(), shot.passes.end(), "behind shading"), shot.passes.end())
        << render::methodName(m) << " draws what lies behind the glass first";
  }
}

// With no displacement the lookup behind the glass is the straight-through
// view: exactly what `none` draws (the eye's glass is untinted).
TEST_F(MethodImages, NormalOffsetOfStrengthZeroSeesStraightThrough) {
  scene::Scene eye = eyeWith(1.376f);
  Comparison c = compare(draw(context(), eye, Method::NormalOffset, 0.0f).image, draw(context(), eye, Method::None).image);
  EXPECT_EQ(c.withinOne, c.pixels) << c.firstMismatches;
}

// At IOR 1 the refracted ray is the view ray, so the point where it meets the
// plane behind projects back onto the fragment's own pixel.
TEST_F(MethodImages, IrisPlaneAtIorOneSeesStraightThrough) {
  scene::Scene eye = eyeWith(1.0f);
  EXPECT_GE(shareWithinOne(draw(context(), eye, Method::IrisPlane).image, draw(context(), eye, Method::None).image),
            0.999);
}

TEST_F(MethodImages, IrisPlaneBendsTheViewAtTheCorneasIor) {
  scene::Scene eye = eyeWith(1.376f);
  EXPECT_LT(shareWithinOne(draw(context(), eye, Method::IrisPlane).image, draw(context(), eye, Method::None).image),
            0.99);
}

// The peer: the same rays and shading through the driver's ray tracing. It
// finds the same first hits as snell's trees and draws the same picture.
TEST(DriverRt, DrawsTheTracesPictureWithTheSameFirstHits) {
  vk::ContextDesc desc;
  desc.applicationName = "snell tests (driver-rt)";
  desc.validation = true;
  desc.synchronizationValidation = true;
  desc.driverRayTracing = true;
  std::unique_ptr<vk::Context> context = vk::Context::create(desc);
  if (!context->caps().driverRayTracing) {
    GTEST_SKIP() << context->facts().name << " offers no ray tracing pipelines (VK_KHR_ray_tracing_pipeline)";
  }
  scene::Scene eye = eyeWith(1.376f);
  scene::Pose pose = scene::evaluate(eye, 1.5);
  scene::View view = scene::resolveView(eye, pose, {});
  render::FrameSettings settings{kWidth, kHeight, view, glm::vec3(scene::kDefaultBackground), gpu::kDefaultMaxInterfaces};
  std::vector<render::ViewPixels> pixels;
  for (Method m : {Method::Trace, Method::DriverRt}) {
    render::Renderer renderer(*context, eye, pose);
    render::FrameRequest request;
    request.pose = &pose;
    request.views.push_back(render::methodView(m, settings, {}));
    request.views.back().aov = true;
    request.readbacks.push_back({.view = 0});
    pixels.push_back(renderer.wait(renderer.submit(request)).views.at(0));
  }
  size_t agreeing = 0;
  for (size_t i = 0; i < pixels[0].aov.size(); ++i) {
    agreeing += pixels[0].aov[i].instance == pixels[1].aov[i].instance &&
                pixels[0].aov[i].primitive == pixels[1].aov[i].primitive;
  }
  EXPECT_GE(double(agreeing) / double(pixels[0].aov.size()), 0.999);
  EXPECT_GE(shareWithinOne(io::toSrgb8({kWidth, kHeight, pixels[1].trace}), io::toSrgb8({kWidth, kHeight, pixels[0].trace})),
            0.999);
  EXPECT_EQ(context->validationMessageCount(), 0u);
}

// The glass RMSE the benchmark's JSON gives `method`; -1 when it has none.
double glassRmse(const io::Json& json, const std::string& method) {
  for (const io::Json& row : json.at("methods")) {
    if (row.at("method") == method && row.contains("glass")) return row.at("glass").at("rmse").get<double>();
  }
  return -1.0;
}

TEST(BenchMethods, WritesJsonAndAChartWithOnePointPerMethodAndRefractionMatters) {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / "snell_bench_methods";
  fs::create_directories(dir);
  fs::path json = dir / "methods.json", svg = dir / "methods.svg";
  CommandRun run = runCommand(std::string(SNELL_BINARY) + " bench methods --size 96x72 --frames 3 --json " +
                              shellQuoted(json.string()) + " --svg " + shellQuoted(svg.string()));
  ASSERT_EQ(run.exitCode, 0) << run.output;
  std::ifstream in(json);
  io::Json parsed = io::Json::parse(in);
  std::string j = parsed.dump();
  for (const render::MethodInfo& m : render::methods()) {
    EXPECT_NE(j.find("\"method\":\"" + std::string(m.name) + "\""), std::string::npos) << m.name;
  }
  double traceError = glassRmse(parsed, "trace");
  double noneError = glassRmse(parsed, "none");
  ASSERT_GE(traceError, 0.0) << j;
  EXPECT_GT(noneError, 10.0 * traceError) << "seeing straight through the cornea is visibly wrong: " << j;
  CommandRun lint = runCommand("xmllint --noout " + shellQuoted(svg.string()));
  EXPECT_EQ(lint.exitCode, 0) << lint.output;
  std::ifstream chart(svg);
  std::stringstream svgText;
  svgText << chart.rdbuf();
  std::string s = svgText.str();
  size_t circles = 0;
  for (size_t at = s.find("<circle"); at != std::string::npos; at = s.find("<circle", at + 1)) ++circles;
  size_t unsupported = 0;
  for (size_t at = j.find("\"unsupported\""); at != std::string::npos; at = j.find("\"unsupported\"", at + 1)) ++unsupported;
  EXPECT_EQ(circles, render::methods().size() - unsupported) << "one point per method that ran";
  fs::remove_all(dir);
}

TEST_F(MethodImages, BenchMethodsPipelineStatsListTheTracePipelinesWhereTheDriverOffersThem) {
  CommandRun run = runCommand(std::string(SNELL_BINARY) +
                              " bench methods --methods trace --size 32x24 --frames 2 --no-reference --pipeline-stats");
  ASSERT_EQ(run.exitCode, 0) << run.output;
  bool listed = run.output.find("trace pipelines, as the driver compiled them:\n  trace (optics 0x") != std::string::npos;
  EXPECT_EQ(listed, context().facts().pipelineStatistics) << run.output;
}

}  // namespace
}  // namespace snell::test
