// Baked refraction maps (bake/refraction_bake.h): what the trace bakes, what
// the raster pass's refraction-map method draws from it, the DCC route, and
// the map files.
#include "gpu_test.h"
#include "golden_support.h"

#include "bake/map_file.h"
#include "bake/refraction_bake.h"
#include "io/image_compare.h"
#include "io/image_file.h"
#include "render/method.h"
#include "render/one_view.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/view.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace snell::test {
namespace {

constexpr uint32_t kWidth = 160, kHeight = 120;

struct Baked {
  scene::Scene scene = eyeWith(1.376f);
  scene::Pose pose;
  render::FrameSettings settings;
  bake::RefractionBake bake;
};

// The eye at `time`, baked from its own camera.
Baked bakeEye(vk::Context& context, double time = 0.0) {
  Baked b;
  b.pose = scene::evaluate(b.scene, time);
  b.settings = {kWidth, kHeight, scene::resolveView(b.scene, b.pose, {}), glm::vec3(scene::kDefaultBackground), 8};
  render::Renderer renderer(context, b.scene, b.pose);
  b.bake = render::bakeRefraction(renderer, b.pose, b.settings);
  return b;
}

// refraction-map's picture of `s` at `pose` from `settings`' view, with `map`.
io::Rgb8Image drawWithMap(vk::Context& context, const scene::Scene& s, const scene::Pose& pose,
                           const render::FrameSettings& settings, const render::RefractionMapBuffer& map) {
  render::Renderer renderer(context, s, pose);
  render::RasterOptions raster;
  raster.refractionMap = &map;
  render::FrameRequest request;
  request.pose = &pose;
  request.views.push_back(render::methodView(render::Method::RefractionMap, settings, raster));
  request.readbacks.push_back({.view = 0});
  const render::FrameResult& result = renderer.wait(renderer.submit(request));
  return io::toSrgb8({settings.width, settings.height, result.views.at(0).composite});
}

io::Rgb8Image traceOf(vk::Context& context, const scene::Scene& s, const scene::Pose& pose,
                       const render::FrameSettings& settings) {
  render::Renderer renderer(context, s, pose);
  render::RenderedFrame frame = render::renderFrame(renderer, pose, settings);
  return io::toSrgb8({settings.width, settings.height, frame.rgba});
}

// The difference over the pixels the bake saw glass in.
io::ImageDifference glassError(const io::Rgb8Image& got, const io::Rgb8Image& want, const bake::RefractionBake& bake) {
  std::vector<bool> glass(bake.texels.size());
  for (size_t i = 0; i < glass.size(); ++i) glass[i] = bake.coverage(i) != bake::Coverage::Empty;
  return io::compareImages(got, want, &glass);
}

// The GPU tests of baking the refraction map on the GPU.
class RefractionBake : public GpuTest {};

TEST_F(RefractionBake, TheBakedEyeMarksItsGlassAndWhereItLandsOnTheIris) {
  Baked b = bakeEye(context());
  size_t lands = b.bake.count(bake::Coverage::Lands), marked = b.bake.count(bake::Coverage::Marked);
  std::printf("%s\n", bake::describe(b.bake, b.scene).c_str());
  ASSERT_NE(b.bake.behindMaterial, gpu::kNoHit);
  EXPECT_EQ(b.scene.materials[b.bake.behindMaterial].name, "iris");
  EXPECT_GT(lands, 1000u);
  // Through the pupil the path lands on the untextured dark behind: marked, not guessed.
  EXPECT_GT(marked, 0u);
  for (size_t i = 0; i < b.bake.texels.size(); ++i) {
    const gpu::RefractionTexel& t = b.bake.texels[i];
    if (b.bake.coverage(i) == bake::Coverage::Marked) {
      EXPECT_TRUE(t.material != b.bake.behindMaterial || std::isnan(t.u)) << "pixel " << i;
    }
    if (b.bake.coverage(i) == bake::Coverage::Empty) {
      EXPECT_EQ(t.shine.w, 0.0f) << "pixel " << i;
    }
  }
}

// At the pose and view it was baked at, the map redraws the trace: each
// glass pixel is the shine plus the weight times the same texel.
TEST_F(RefractionBake, TheMapRedrawsTheTraceAtTheBakedPoseAndView) {
  Baked b = bakeEye(context());
  render::RefractionMapBuffer map = render::uploadRefractionMap(context(), b.bake);
  io::Rgb8Image drawn = drawWithMap(context(), b.scene, b.pose, b.settings, map);
  io::Rgb8Image traced = traceOf(context(), b.scene, b.pose, b.settings);
  io::ImageDifference e = glassError(drawn, traced, b.bake);
  std::printf("glass pixels: %llu, within 1/255 of the trace: %llu, worst %d/255\n", (unsigned long long)e.pixels,
              (unsigned long long)(e.pixels - e.over1), e.maximum);
  ASSERT_GT(e.pixels, 1000u);
  EXPECT_LE(double(e.over1), 0.001 * double(e.pixels));
  EXPECT_LE(e.maximum, 2);
}

// The renderer keeps the map it baked: a refraction-map view that names no
// map of its own draws with it, as it would with the same map handed over.
TEST_F(RefractionBake, ARendererDrawsWithTheRefractionMapItBakedLast) {
  Baked b = bakeEye(context());
  render::Renderer renderer(context(), b.scene, b.pose);
  renderer.bakeRefractionMap(b.pose, b.settings);
  render::FrameRequest request;
  request.pose = &b.pose;
  request.views.push_back(render::methodView(render::Method::RefractionMap, b.settings, render::RasterOptions{}));
  request.readbacks.push_back({.view = 0});
  const render::FrameResult& result = renderer.wait(renderer.submit(request));
  io::Rgb8Image kept = io::toSrgb8({kWidth, kHeight, result.views.at(0).composite});
  render::RefractionMapBuffer map = render::uploadRefractionMap(context(), b.bake);
  EXPECT_EQ(kept.rgb, drawWithMap(context(), b.scene, b.pose, b.settings, map).rgb);
}

TEST_F(RefractionBake, TheRefractionMapMethodWithoutABakedMapIsAnError) {
  Baked b = bakeEye(context());
  render::Renderer renderer(context(), b.scene, b.pose);
  render::FrameRequest request;
  request.pose = &b.pose;
  request.views.push_back(render::methodView(render::Method::RefractionMap, b.settings, render::RasterOptions{}));
  try {
    renderer.submit(request);
    FAIL() << "a refraction-map view drew without a map";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("Renderer::bakeRefractionMap"), std::string::npos) << e.what();
  }
}

// Baked at 0 s and drawn at later times, the eye has moved under the map:
// the error grows with the drift, and the method does no trace.
TEST_F(RefractionBake, TheMapsErrorGrowsAsThePoseDriftsFromTheBakedOne) {
  Baked b = bakeEye(context());
  render::RefractionMapBuffer map = render::uploadRefractionMap(context(), b.bake);
  double duration = scene::animationDuration(b.scene);
  ASSERT_GT(duration, 0.0);
  std::vector<double> within;
  for (double t : {0.0, 0.1 * duration, 0.5 * duration}) {
    scene::Pose pose = scene::evaluate(b.scene, t);
    io::ImageDifference e = glassError(drawWithMap(context(), b.scene, pose, b.settings, map),
                              traceOf(context(), b.scene, pose, b.settings), b.bake);
    within.push_back(1.0 - e.share(e.over8));
    std::printf("%.2f s: %.1f%% of the baked glass pixels within 8/255 of the trace\n", t, 100.0 * within.back());
  }
  EXPECT_GT(within[0], 0.999);
  EXPECT_LT(within[2], within[0] - 0.05) << "half the animation later the map no longer fits";
}

// The DCC route: the texture behind replaced by a UV gradient, rendered and
// read back, gives the UVs the trace reports, within the gradient's texel
// and the encoding's step; the tiled gradient (sky8's codes) is the finer.
TEST_F(RefractionBake, TheDccRouteAgreesWithTheDirectBake) {
  Baked b = bakeEye(context());
  bake::DecodedMap direct = bake::storedMap(b.bake, b.scene);
  struct Route {
    uint32_t size;
    bool tiled;
    double bound;  // half a gradient texel, half the code's step, float rounding
  };
  double worstOf[2] = {0.0, 0.0};
  for (const Route& r : {Route{256, false, 0.5 / 256 + 0.5 / 255 + 1e-5}, Route{1024, true, 0.5 / 1024 + 8.0 / 65025 + 1e-5}}) {
    bake::DecodedMap dcc = bake::bakeThroughGradient(context(), b.scene, b.pose, b.settings, b.bake, r.size, r.tiled);
    size_t compared = 0, within = 0;
    double worst = 0.0;
    for (size_t i = 0; i < direct.uv.size(); ++i) {
      ASSERT_EQ(dcc.coverage[i], direct.coverage[i]);
      if (direct.coverage[i] != bake::Coverage::Lands) continue;
      double d = std::max(std::abs(dcc.uv[i].x - direct.uv[i].x), std::abs(dcc.uv[i].y - direct.uv[i].y));
      ++compared;
      within += d <= r.bound;
      worst = std::max(worst, d);
    }
    std::printf("%s gradient %ux%u: %zu of %zu pixels within %.2g in UV, worst %.3g\n", r.tiled ? "tiled" : "plain",
                r.size, r.size, within, compared, r.bound, worst);
    EXPECT_GE(double(within), 0.999 * double(compared));
    worstOf[r.tiled] = worst;
  }
  EXPECT_LT(4.0 * worstOf[1], worstOf[0]) << "the tiled gradient addresses finer than 8-bit";
}

// Each file encoding written and read back holds the baked UVs within its
// step, and the coverage exactly.
TEST_F(RefractionBake, EachMapFileRoundTripsTheBakedUvsWithinItsStep) {
  Baked b = bakeEye(context());
  bake::DecodedMap want = bake::storedMap(b.bake, b.scene);
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / "snell_bake_files";
  fs::create_directories(dir);
  struct Case {
    bake::Encoding encoding;
    const char* file;
    double bound;
  };
  for (const Case& c : {Case{bake::Encoding::Rg16, "map16.png", 0.5 / 65535 + 1e-9},
                        Case{bake::Encoding::Exr, "map.exr", 1e-7},
                        Case{bake::Encoding::Sky8, "map8.png", 8.0 / 65025 + 1e-9}}) {
    std::string path = (dir / c.file).string();
    try {
      bake::writeMapFile(path, bake::encodeMap(want, c.encoding), c.encoding);
    } catch (const std::runtime_error& e) {
      if (std::string(e.what()).find("no OpenImageIO") == std::string::npos) throw;
      std::printf("%s: skipped, %s\n", c.file, e.what());  // the GPU machine's build carries no OpenImageIO
      continue;
    }
    bake::Encoding read = bake::Encoding::Exr;
    bake::MapPixels pixels = bake::readMapFile(path, read);
    bake::DecodedMap got = bake::decodeMap(pixels, read);
    EXPECT_EQ(read, c.encoding) << c.file;
    ASSERT_EQ(got.coverage.size(), want.coverage.size());
    double worst = 0.0;
    for (size_t i = 0; i < want.coverage.size(); ++i) {
      ASSERT_EQ(got.coverage[i], want.coverage[i]) << c.file << " pixel " << i;
      if (want.coverage[i] != bake::Coverage::Lands) continue;
      worst = std::max({worst, std::abs(got.uv[i].x - want.uv[i].x), std::abs(got.uv[i].y - want.uv[i].y)});
    }
    std::printf("%s: worst UV error %.3g (bound %.3g)\n", c.file, worst, c.bound);
    EXPECT_LE(worst, c.bound) << c.file;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace snell::test
