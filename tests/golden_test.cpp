// Golden images: the GPU trace against pictures made by the CPU double-
// precision reference (src/ref), with a tolerance stated per image. Each
// golden is also re-rendered by the reference here, so a stale golden fails.
//
//   SNELL_UPDATE_GOLDEN=1 snell_tests --gtest_filter='Golden*'
// rewrites golden/*.png from the reference (never from the GPU).
#include "assets.h"
#include "golden_support.h"
#include "gpu_test.h"

#include "io/image_file.h"
#include "ref/reference_tracer.h"
#include "render/one_view.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/procedural_eye.h"
#include "scene/view.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <sstream>

namespace snell::test {
namespace {

namespace fs = std::filesystem;

struct Case {
  std::string name;
  uint32_t width = 192, height = 144;
  Tolerance tolerance;
  std::function<scene::Scene()> makeScene;
  double time = 0.0;
  scene::ViewRequest view;
};

std::vector<Case> cases() {
  std::vector<Case> list;
  Tolerance eye{0.999, 8};
  list.push_back({"eye_front", 192, 144, eye, [] { return eyeWith(1.376f); }, 0.0, {}});
  scene::ViewRequest grazing;  // 75 degrees off the cornea's axis
  double a = 75.0 * 3.14159265358979 / 180.0;
  grazing.lookAt = scene::LookAt{{0.045 * std::sin(a), 0.0, 0.045 * std::cos(a)}, {0.0, 0.0, 0.006}, {0.0, 1.0, 0.0}};
  grazing.yfov = 0.5;
  list.push_back({"eye_grazing_75deg", 192, 144, eye, [] { return eyeWith(1.376f); }, 0.0, grazing});
  list.push_back({"eye_squashed", 192, 144, eye, [] { return eyeWith(1.376f); }, 1.5, {}});
  list.push_back({"eye_ior_1", 192, 144, eye, [] { return eyeWith(1.0f); }, 0.0, {}});
  scene::ViewRequest prismView;
  prismView.lookAt = scene::LookAt{{0.6, 0.3, -6.0}, {0.6, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  prismView.yfov = 0.6;
  list.push_back({"prism_total_internal_reflection", 160, 120, {0.999, 64}, prismScene, 0.0, prismView});
  Tolerance models{0.999, 255};  // a silhouette pixel may flip between hit and miss
  list.push_back({"transmission_roughness_test", 192, 144, models,
                  [] { return loadModel("TransmissionRoughnessTest/glTF-Binary/TransmissionRoughnessTest.glb"); }, 0.0, {}});
  list.push_back({"iridescence_suzanne", 192, 144, models,
                  [] { return loadModel("IridescenceSuzanne/glTF-Binary/IridescenceSuzanne.glb"); }, 0.0, {}});
  // Two vases: the left one's glass is alpha-blended (BLEND), the right
  // one's transmissive; the leaves are alpha-masked and normal-mapped. The
  // glass, water and stems share coincident faces; which of two faces at the
  // same distance a ray meets first is decided by rounding, so the GPU
  // (float) and the reference (double) part ways on 0.1% of pixels.
  list.push_back({"glass_vase_flowers", 144, 192, {0.995, 255},
                  [] { return loadModel("GlassVaseFlowers/glTF-Binary/GlassVaseFlowers.glb"); }, 0.0, {}});
  // The cornea hands over to the aqueous 0.55 mm in; the aqueous outranks it (nested media).
  list.push_back({"eye_aqueous", 192, 144, eye, eyeWithAqueous, 0.0, {}});
  scene::ViewRequest stepView;
  stepView.lookAt = scene::LookAt{{0.0, 0.0, 5.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  stepView.yfov = 0.7;
  // A hard IOR step: a pixel on the step may take either side.
  list.push_back({"ior_texture_step", 160, 120, {0.995, 255}, iorStepScene, 0.0, stepView});
  list.push_back({"attenuation_test", 192, 144, models,
                  [] { return loadModel("AttenuationTest/glTF-Binary/AttenuationTest.glb"); }, 0.0, {}});
  return list;
}

// A case's scene at its time and the view it is seen from. Built in place
// and never moved: the pose's draw items point at the scene.
struct Shot {
  explicit Shot(const Case& c)
      : scene(c.makeScene()), pose(scene::evaluate(scene, c.time)), view(scene::resolveView(scene, pose, c.view)) {}
  Shot(const Shot&) = delete;
  Shot& operator=(const Shot&) = delete;
  scene::Scene scene;
  scene::Pose pose;
  scene::View view;
};

class Golden : public GpuTest, public ::testing::WithParamInterface<Case> {};

TEST_P(Golden, GpuTraceMatchesTheReferenceGolden) {
  const Case& c = GetParam();
  const Shot shot(c);
  const auto& [s, pose, view] = std::tie(shot.scene, shot.pose, shot.view);
  const fs::path goldenPath = goldenDir() / (c.name + ".png");
  const char* update = std::getenv("SNELL_UPDATE_GOLDEN");
  if (update && std::string(update) == "1") io::writeRgb8(goldenPath.string(), referenceImage(s, pose, view, c.width, c.height));
  ASSERT_TRUE(fs::exists(goldenPath)) << goldenPath << " is missing (SNELL_UPDATE_GOLDEN=1 makes it from the reference)";
  io::Rgb8Image golden = io::readRgb8(goldenPath.string());
  ASSERT_EQ(golden.width, c.width);
  ASSERT_EQ(golden.height, c.height);

  render::Renderer renderer(context(), s, pose);
  render::FrameSettings settings{c.width, c.height, view, glm::vec3(scene::kDefaultBackground), gpu::kDefaultMaxInterfaces};
  render::RenderedFrame frame = render::renderFrame(renderer, pose, settings);
  io::Rgb8Image gpu = io::toSrgb8({c.width, c.height, frame.rgba});
  Comparison result = compare(gpu, golden);
  double share = double(result.withinOne) / double(result.pixels);
  RecordProperty("within_one", std::to_string(share));
  RecordProperty("max_difference", result.maxDifference);
  std::printf("%s: %.4f%% of pixels within 1/255, max difference %d/255\n", c.name.c_str(), 100.0 * share,
              result.maxDifference);
  bool pass = share >= c.tolerance.withinOne && result.maxDifference <= c.tolerance.maxDifference;
  if (!pass) {
    fs::path out = scratchDir("golden-" + c.name);
    io::writeRgb8((out / "gpu.png").string(), gpu);
    io::writeRgb8((out / "diff.png").string(), result.diff);
    ADD_FAILURE() << c.name << ": " << 100.0 * share << "% of pixels within 1/255 (need "
                  << 100.0 * c.tolerance.withinOne << "%), max difference " << result.maxDifference << " (allowed "
                  << c.tolerance.maxDifference << ")\nfirst mismatches:\n"
                  << result.firstMismatches << "GPU image and diff written to " << out;
  }
}

TEST_P(Golden, GoldenIsWhatTheReferenceRendersToday) {
  const Case& c = GetParam();
  const Shot shot(c);
  const fs::path goldenPath = goldenDir() / (c.name + ".png");
  ASSERT_TRUE(fs::exists(goldenPath)) << goldenPath << " is missing";
  Comparison result = compare(referenceImage(shot.scene, shot.pose, shot.view, c.width, c.height),
                              io::readRgb8(goldenPath.string()));
  // Compilers may round the last bit differently; anything more means the golden is stale.
  EXPECT_LE(result.maxDifference, 1) << c.name << ": the committed golden is not what src/ref renders\n"
                                      << result.firstMismatches;
}

INSTANTIATE_TEST_SUITE_P(Images, Golden, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

// The GPU tests of the eye with and without its glass.
class EyeGlass : public GpuTest {};

// IOR 1 bends nothing: the cornea must vanish, on the GPU as in the reference.
TEST_F(EyeGlass, EyeWithIorOneEqualsTheEyeWithoutItsTransmissiveFaces) {
  auto render = [&](const scene::Scene& s) {
    scene::Pose pose = scene::evaluate(s, 0.0);
    scene::View view = scene::resolveView(s, pose, {});
    render::Renderer renderer(context(), s, pose);
    render::RenderedFrame frame = render::renderFrame(renderer, pose, {192, 144, view, glm::vec3(scene::kDefaultBackground), 8});
    return io::toSrgb8({192, 144, frame.rgba});
  };
  Comparison result = compare(render(eyeWith(1.0f)), render(eyeWithoutCorneaTip()));
  double share = double(result.withinOne) / double(result.pixels);
  std::printf("IOR 1 vs no cornea tip: %.4f%% within 1/255, max %d\n", 100.0 * share, result.maxDifference);
  EXPECT_GE(share, 0.9995) << result.firstMismatches;
  EXPECT_LE(result.maxDifference, 8) << result.firstMismatches;
}

}  // namespace
}  // namespace snell::test
