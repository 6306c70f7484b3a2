// Shared by the golden tests of the trace (golden_test.cpp) and of the
// viewport composite (viewport_test.cpp).
#include "golden_support.h"

#include <glm/gtc/matrix_transform.hpp>

#include "assets.h"

#include "io/image_compare.h"
#include "ref/reference_tracer.h"
#include "scene/gltf_loader.h"
#include "scene/procedural_eye.h"
#include "scene/scene_builder.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace snell::test {

io::Rgb8Image referenceImage(const scene::Scene& s, const scene::Pose& pose, const scene::View& view, uint32_t width,
                              uint32_t height) {
  ref::ReferenceSettings settings;
  settings.width = width;
  settings.height = height;
  settings.view = view;
  ref::ReferenceImage r = ref::renderReference(s, pose, settings);
  io::LinearImage linear{width, height, {}};
  for (const glm::dvec3& colour : r.color) linear.rgba.emplace_back(glm::vec3(colour), 1.0f);
  return io::toSrgb8(linear);
}

// SNELL_GOLDEN_DIR in the environment wins: the GPU machine has the checkout elsewhere.
std::filesystem::path goldenDir() {
  const char* override = std::getenv("SNELL_GOLDEN_DIR");
  return override ? std::filesystem::path(override) : std::filesystem::path(SNELL_SOURCE_DIR) / "golden";
}

Comparison compare(const io::Rgb8Image& got, const io::Rgb8Image& want) {
  std::vector<uint8_t> worst;
  io::ImageDifference d = io::compareImages(got, want, nullptr, &worst);
  Comparison c;
  c.pixels = d.pixels;
  c.withinOne = d.pixels - d.over1;
  c.maxDifference = d.maximum;
  // The diff image: mismatches in red, brighter for larger ones, over a dim copy of the golden.
  c.diff = {want.width, want.height, std::vector<uint8_t>(c.pixels * 3, 0)};
  int listed = 0;
  for (size_t i = 0; i < c.pixels; ++i) {
    if (worst[i] <= 1) {
      for (size_t k = 0; k < 3; ++k) c.diff.rgb[3 * i + k] = uint8_t(want.rgb[3 * i + k] / 4);
      continue;
    }
    c.diff.rgb[3 * i] = uint8_t(std::min(255, 64 + 4 * int(worst[i])));
    if (listed++ < 5) {
      std::ostringstream line;
      line << "  pixel (" << i % want.width << ", " << i / want.width << "): GPU " << int(got.rgb[3 * i]) << ","
           << int(got.rgb[3 * i + 1]) << "," << int(got.rgb[3 * i + 2]) << " golden " << int(want.rgb[3 * i]) << ","
           << int(want.rgb[3 * i + 1]) << "," << int(want.rgb[3 * i + 2]) << "\n";
      c.firstMismatches += line.str();
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
  scene::Material glass = scene::clearGlass("glass", 1.5f);
  scene::Material red, blue, green;
  red.baseColorFactor = {0.9f, 0.15f, 0.1f, 1};
  blue.baseColorFactor = {0.1f, 0.2f, 0.9f, 1};
  green.baseColorFactor = {0.2f, 0.8f, 0.2f, 1};
  // Self-lit walls: what the prism shows does not depend on where the light is.
  red.emissiveFactor = {0.6f, 0.1f, 0.05f};
  blue.emissiveFactor = {0.05f, 0.1f, 0.6f};
  green.emissiveFactor = {0.1f, 0.4f, 0.1f};
  s.materials = {glass, red, blue, green};
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
  addFlatShape(s, p, idx, 0);
  // Walls, each facing the prism: red behind the camera's left (where reflected rays go), blue far behind,
  // green floor.
  addFlatShape(s, {{-6, -3, -1}, {-6, -3, 5}, {-6, 3, 5}, {-6, 3, -1}}, {0, 2, 1, 0, 3, 2}, 1);  // faces +x
  addFlatShape(s, {{-6, -3, 8}, {6, -3, 8}, {6, 3, 8}, {-6, 3, 8}}, {0, 2, 1, 0, 3, 2}, 2);
  addFlatShape(s, {{-6, -3, -8}, {6, -3, -8}, {6, -3, 8}, {-6, -3, 8}}, {0, 2, 1, 0, 3, 2}, 3);
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

scene::Scene eyeWithAqueous() {
  scene::EyeOptions options;
  options.aqueous = true;
  return scene::makeEye(options);
}

int addFlatShape(scene::Scene& s, const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                 int material, const glm::mat4& world) {
  scene::Shape shape = scene::flatShape(positions, indices, material);
  shape.name = "shape" + std::to_string(s.shapes.size());
  scene::addRootShape(s, std::move(shape), world);
  return int(s.shapes.size()) - 1;
}

scene::Scene iorStepScene() {
  scene::Scene s;
  s.source = "IOR texture step";
  scene::Texture step;  // left texel 0, right texel 255, nearest: a hard step at u = 0.5
  step.name = "ior step";
  step.width = 2;
  step.height = 1;
  step.rgba = {0, 0, 0, 255, 255, 255, 255, 255};
  step.repeatS = step.repeatT = false;
  step.linearFilter = false;
  scene::Texture checker;
  checker.name = "checker";
  checker.width = checker.height = 8;
  checker.repeatS = checker.repeatT = true;
  checker.linearFilter = false;
  for (uint32_t i = 0; i < 64; ++i) {
    uint8_t v = ((i % 8) + (i / 8)) % 2 ? 230 : 40;
    checker.rgba.insert(checker.rgba.end(), {v, uint8_t(v / 2), uint8_t(255 - v), 255});
  }
  s.textures = {step, checker};
  scene::Material glass = scene::clearGlass("stepped glass", 1.0f);
  glass.iorTexture.texture = 0;
  glass.iorScale = 0.5f;
  scene::Material wall;
  wall.name = "checker wall";
  wall.baseColorFactor = {0, 0, 0, 1};
  wall.emissiveFactor = glm::vec3(1.0f);
  wall.emissiveTexture.texture = 1;
  s.materials = {glass, wall};
  std::vector<glm::vec3> p;
  std::vector<uint32_t> idx;
  scene::addBox({-1, -1, -0.3f}, {1, 1, 0.3f}, p, idx);
  addFlatShape(s, p, idx, 0, glm::rotate(glm::mat4(1.0f), 0.5f, glm::vec3(0.3f, 1.0f, 0.0f)));
  addFlatShape(s, {{-4, -4, -3}, {4, -4, -3}, {4, 4, -3}, {-4, 4, -3}}, {0, 1, 2, 0, 2, 3}, 1);
  scene::Light light;  // shines from behind the wall: the wall shows only its own light
  light.type = scene::LightType::Directional;
  s.lights = {light};
  scene::Node lightNode;
  lightNode.light = 0;
  lightNode.rotation = glm::angleAxis(3.14159265f, glm::vec3(0, 1, 0));
  s.nodes.push_back(lightNode);
  s.roots.push_back(int(s.nodes.size()) - 1);
  return s;
}

render::CompositeFrame compositeOf(render::Renderer& renderer, const scene::Pose& pose, const scene::View& view,
                                   uint32_t width, uint32_t height) {
  return render::renderComposite(renderer, pose, {width, height, view, glm::vec3(scene::kDefaultBackground), 8},
                                 {});
}

void addGlassBox(scene::Scene& s, glm::vec3 lo, glm::vec3 hi, float ior) {
  scene::Material glass = scene::clearGlass("glass box", ior);
  s.materials.push_back(glass);
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  scene::addBox(lo, hi, positions, indices);
  addFlatShape(s, positions, indices, int(s.materials.size()) - 1, glm::mat4(1.0f));
}

scene::Scene loadModel(const std::string& relative) {
  scene::LoadOptions load;
  load.ignoredExtensions = {"KHR_materials_iridescence"};  // Suzanne's film; her glass is what counts here
  return scene::loadGltf(test::model(relative), load);
}

}  // namespace snell::test
