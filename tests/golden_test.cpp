// Golden images: the GPU trace against pictures made by the CPU double-
// precision reference (src/ref), with a tolerance stated per image. Each
// golden is also re-rendered by the reference here, so a stale golden fails.
//
//   SNELL_UPDATE_GOLDEN=1 snell_tests --gtest_filter='Golden*'
// rewrites golden/*.png from the reference (never from the GPU).
#include "assets.h"
#include "gpu_test.h"

#include "cli/image_file.h"
#include "ref/reference_tracer.h"
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

struct Tolerance {
  double withinOne = 0.999;  ///< share of pixels whose channels all differ by at most 1/255
  int maxDifference = 255;   ///< the largest channel difference allowed anywhere, in 1/255
};

struct Case {
  std::string name;
  uint32_t width = 192, height = 144;
  Tolerance tolerance;
  std::function<scene::Scene()> makeScene;
  double time = 0.0;
  scene::ViewRequest view;
};

// SNELL_GOLDEN_DIR in the environment wins: the GPU machine has the checkout elsewhere.
fs::path goldenDir() {
  const char* override = std::getenv("SNELL_GOLDEN_DIR");
  return override ? fs::path(override) : fs::path(SNELL_SOURCE_DIR) / "golden";
}

cli::Rgb8Image referenceImage(const scene::Scene& s, const scene::Pose& pose, const scene::View& view, const Case& c) {
  ref::ReferenceSettings settings;
  settings.width = c.width;
  settings.height = c.height;
  settings.view = view;
  ref::ReferenceImage r = ref::renderReference(s, pose, settings);
  cli::LinearImage linear{c.width, c.height, {}};
  for (const glm::dvec3& colour : r.color) linear.rgba.emplace_back(glm::vec3(colour), 1.0f);
  return cli::toSrgb8(linear);
}

struct Comparison {
  size_t pixels = 0, withinOne = 0;
  int maxDifference = 0;
  std::string firstMismatches;
  cli::Rgb8Image diff;
};

Comparison compare(const cli::Rgb8Image& got, const cli::Rgb8Image& want) {
  Comparison c;
  c.pixels = size_t(want.width) * want.height;
  c.diff = {want.width, want.height, std::vector<uint8_t>(c.pixels * 3, 0)};
  int listed = 0;
  for (size_t i = 0; i < c.pixels; ++i) {
    int worst = 0;
    for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(int(got.rgb[3 * i + k]) - int(want.rgb[3 * i + k])));
    c.maxDifference = std::max(c.maxDifference, worst);
    if (worst <= 1) {
      ++c.withinOne;
      continue;
    }
    // The diff image: mismatches in red, brighter for larger ones, over a dim copy of the golden.
    c.diff.rgb[3 * i] = uint8_t(std::min(255, 64 + 4 * worst));
    if (listed++ < 5) {
      std::ostringstream line;
      line << "  pixel (" << i % want.width << ", " << i / want.width << "): GPU " << int(got.rgb[3 * i]) << ","
           << int(got.rgb[3 * i + 1]) << "," << int(got.rgb[3 * i + 2]) << " golden " << int(want.rgb[3 * i]) << ","
           << int(want.rgb[3 * i + 1]) << "," << int(want.rgb[3 * i + 2]) << "\n";
      c.firstMismatches += line.str();
    }
  }
  for (size_t i = 0; i < c.pixels; ++i) {
    if (c.diff.rgb[3 * i] == 0) {
      for (int k = 0; k < 3; ++k) c.diff.rgb[3 * i + k] = uint8_t(want.rgb[3 * i + k] / 4);
    }
  }
  return c;
}

scene::Scene eyeWith(float ior) {
  scene::EyeOptions options;
  options.ior = ior;
  return scene::makeEye(options);
}

// The eye with every transmissive face taken out: what IOR 1 must look like.
scene::Scene eyeWithoutCorneaTip() {
  scene::Scene s = scene::makeEye();
  for (scene::Shape& shape : s.shapes) {
    if (shape.material >= 0 && s.materials[size_t(shape.material)].refractive()) shape.indices.clear();
  }
  return s;
}

// A right-angle glass prism seen through one leg: rays enter head-on, meet
// the hypotenuse at 45 degrees (beyond glass's 41.8-degree critical angle),
// reflect inside and leave through the other leg towards a coloured wall.
scene::Scene prismScene() {
  scene::Scene s;
  s.source = "prism";
  scene::Material glass;
  glass.name = "glass";
  glass.transmission = 1.0f;
  glass.ior = 1.5f;
  scene::Material red, blue, green;
  red.baseColorFactor = {0.9f, 0.15f, 0.1f, 1};
  blue.baseColorFactor = {0.1f, 0.2f, 0.9f, 1};
  green.baseColorFactor = {0.2f, 0.8f, 0.2f, 1};
  // Self-lit walls: what the prism shows does not depend on where the light is.
  red.emissiveFactor = {0.6f, 0.1f, 0.05f};
  blue.emissiveFactor = {0.05f, 0.1f, 0.6f};
  green.emissiveFactor = {0.1f, 0.4f, 0.1f};
  s.materials = {glass, red, blue, green};
  auto addShape = [&](std::vector<glm::vec3> p, std::vector<uint32_t> idx, int material) {
    scene::Shape shape;
    shape.name = "shape" + std::to_string(s.shapes.size());
    shape.material = material;
    shape.positions = p;
    shape.indices = idx;
    shape.normals.assign(p.size(), glm::vec3(0.0f));
    for (size_t t = 0; t + 2 < idx.size(); t += 3) {  // flat shading: faces share no vertices
      glm::vec3 n = glm::normalize(glm::cross(p[idx[t + 1]] - p[idx[t]], p[idx[t + 2]] - p[idx[t]]));
      for (int k = 0; k < 3; ++k) shape.normals[idx[t + size_t(k)]] = n;
    }
    int index = int(s.shapes.size());
    s.shapes.push_back(shape);
    scene::Mesh mesh;
    mesh.shapes = {index};
    s.meshes.push_back(mesh);
    scene::Node node;
    node.mesh = int(s.meshes.size()) - 1;
    s.nodes.push_back(node);
    s.roots.push_back(int(s.nodes.size()) - 1);
  };
  // Prism: right angle at (0,0) in xz, legs along +x and +z, extruded along y.
  std::vector<glm::vec3> corners = {{0, -1, 0}, {2, -1, 0}, {0, -1, 2}, {0, 1, 0}, {2, 1, 0}, {0, 1, 2}};
  auto quad = [&](int a, int b, int c, int d, std::vector<glm::vec3>& p, std::vector<uint32_t>& idx) {
    uint32_t base = uint32_t(p.size());
    for (int v : {a, b, c, d}) p.push_back(corners[size_t(v)]);
    idx.insert(idx.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  };
  std::vector<glm::vec3> p;
  std::vector<uint32_t> idx;
  // Wound counter-clockwise seen from outside: the geometric normal tells a
  // ray entering the glass from one leaving it.
  quad(0, 3, 4, 1, p, idx);  // leg on z = 0 (faces -z)
  quad(0, 2, 5, 3, p, idx);  // leg on x = 0 (faces -x)
  quad(1, 4, 5, 2, p, idx);  // hypotenuse
  uint32_t base = uint32_t(p.size());
  for (int v : {0, 1, 2, 3, 5, 4}) p.push_back(corners[size_t(v)]);
  idx.insert(idx.end(), {base, base + 1, base + 2, base + 3, base + 4, base + 5});  // caps
  addShape(p, idx, 0);
  // Walls: red behind the camera's left (where reflected rays go), blue far behind, green floor.
  addShape({{-6, -3, -1}, {-6, -3, 5}, {-6, 3, 5}, {-6, 3, -1}}, {0, 1, 2, 0, 2, 3}, 1);
  addShape({{-6, -3, 8}, {6, -3, 8}, {6, 3, 8}, {-6, 3, 8}}, {0, 2, 1, 0, 3, 2}, 2);
  addShape({{-6, -3, -8}, {6, -3, -8}, {6, -3, 8}, {-6, -3, 8}}, {0, 2, 1, 0, 3, 2}, 3);
  scene::Light light;
  light.type = scene::LightType::Directional;
  light.intensity = 2.0f;
  s.lights = {light};
  scene::Node lightNode;
  lightNode.light = 0;
  lightNode.rotation = glm::quat(glm::vec3(-0.8f, 0.4f, 0.0f));
  s.nodes.push_back(lightNode);
  s.roots.push_back(int(s.nodes.size()) - 1);
  return s;
}

scene::Scene loadModel(const std::string& relative) {
  scene::LoadOptions load;
  load.ignoredExtensions = {"KHR_materials_iridescence"};  // Suzanne's film; her glass is what counts here
  return scene::loadGltf(test::model(relative), load);
}

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
  // The vase's glass, water and stems share coincident faces; which of two
  // faces at the same distance a ray meets first is decided by rounding, so
  // the GPU (float) and the reference (double) part ways on 4.7% of pixels.
  list.push_back({"glass_vase_flowers", 144, 192, {0.95, 255},
                  [] { return loadModel("GlassVaseFlowers/glTF-Binary/GlassVaseFlowers.glb"); }, 0.0, {}});
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
  Shot shot(c);
  const scene::Scene& s = shot.scene;
  const scene::Pose& pose = shot.pose;
  const scene::View& view = shot.view;
  fs::path goldenPath = goldenDir() / (c.name + ".png");
  const char* update = std::getenv("SNELL_UPDATE_GOLDEN");
  if (update && std::string(update) == "1") cli::writeRgb8(goldenPath.string(), referenceImage(s, pose, view, c));
  ASSERT_TRUE(fs::exists(goldenPath)) << goldenPath << " is missing (SNELL_UPDATE_GOLDEN=1 makes it from the reference)";
  cli::Rgb8Image golden = cli::readRgb8(goldenPath.string());
  ASSERT_EQ(golden.width, c.width);
  ASSERT_EQ(golden.height, c.height);

  render::Renderer renderer(context(), s, pose);
  render::FrameSettings settings{c.width, c.height, view, {0.02f, 0.02f, 0.025f}, gpu::kDefaultMaxInterfaces};
  render::RenderedFrame frame = render::renderFrame(context(), renderer, pose, settings);
  cli::Rgb8Image gpu = cli::toSrgb8({c.width, c.height, frame.rgba});
  Comparison result = compare(gpu, golden);
  double share = double(result.withinOne) / double(result.pixels);
  RecordProperty("within_one", std::to_string(share));
  RecordProperty("max_difference", result.maxDifference);
  std::printf("%s: %.4f%% of pixels within 1/255, max difference %d/255\n", c.name.c_str(), 100.0 * share,
              result.maxDifference);
  bool pass = share >= c.tolerance.withinOne && result.maxDifference <= c.tolerance.maxDifference;
  if (!pass) {
    fs::path out = scratchDir("golden-" + c.name);
    cli::writeRgb8((out / "gpu.png").string(), gpu);
    cli::writeRgb8((out / "diff.png").string(), result.diff);
    ADD_FAILURE() << c.name << ": " << 100.0 * share << "% of pixels within 1/255 (need "
                  << 100.0 * c.tolerance.withinOne << "%), max difference " << result.maxDifference << " (allowed "
                  << c.tolerance.maxDifference << ")\nfirst mismatches:\n"
                  << result.firstMismatches << "GPU image and diff written to " << out;
  }
}

TEST_P(Golden, GoldenIsWhatTheReferenceRendersToday) {
  const Case& c = GetParam();
  Shot shot(c);
  const scene::Scene& s = shot.scene;
  const scene::Pose& pose = shot.pose;
  const scene::View& view = shot.view;
  fs::path goldenPath = goldenDir() / (c.name + ".png");
  ASSERT_TRUE(fs::exists(goldenPath)) << goldenPath << " is missing";
  Comparison result = compare(referenceImage(s, pose, view, c), cli::readRgb8(goldenPath.string()));
  // Compilers may round the last bit differently; anything more means the golden is stale.
  EXPECT_LE(result.maxDifference, 1) << c.name << ": the committed golden is not what src/ref renders\n"
                                      << result.firstMismatches;
}

INSTANTIATE_TEST_SUITE_P(Images, Golden, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

// IOR 1 bends nothing: the cornea must vanish, on the GPU as in the reference.
TEST_F(GpuTest, EyeWithIorOneEqualsTheEyeWithoutItsTransmissiveFaces) {
  auto render = [&](const scene::Scene& s) {
    scene::Pose pose = scene::evaluate(s, 0.0);
    scene::View view = scene::resolveView(s, pose, {});
    render::Renderer renderer(context(), s, pose);
    render::RenderedFrame frame = render::renderFrame(context(), renderer, pose, {192, 144, view, {0.02f, 0.02f, 0.025f}, 8});
    return cli::toSrgb8({192, 144, frame.rgba});
  };
  Comparison result = compare(render(eyeWith(1.0f)), render(eyeWithoutCorneaTip()));
  double share = double(result.withinOne) / double(result.pixels);
  std::printf("IOR 1 vs no cornea tip: %.4f%% within 1/255, max %d\n", 100.0 * share, result.maxDifference);
  EXPECT_GE(share, 0.9995) << result.firstMismatches;
  EXPECT_LE(result.maxDifference, 8) << result.firstMismatches;
}

}  // namespace
}  // namespace snell::test
