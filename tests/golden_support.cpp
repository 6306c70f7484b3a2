// Shared by the golden tests of the trace (golden_test.cpp) and of the
// viewport composite (viewport_test.cpp).
#include "golden_support.h"

#include "assets.h"

#include "ref/reference_tracer.h"
#include "scene/gltf_loader.h"
#include "scene/procedural_eye.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace snell::test {

cli::Rgb8Image referenceImage(const scene::Scene& s, const scene::Pose& pose, const scene::View& view, uint32_t width,
                              uint32_t height) {
  ref::ReferenceSettings settings;
  settings.width = width;
  settings.height = height;
  settings.view = view;
  ref::ReferenceImage r = ref::renderReference(s, pose, settings);
  cli::LinearImage linear{width, height, {}};
  for (const glm::dvec3& colour : r.color) linear.rgba.emplace_back(glm::vec3(colour), 1.0f);
  return cli::toSrgb8(linear);
}

// SNELL_GOLDEN_DIR in the environment wins: the GPU machine has the checkout elsewhere.
std::filesystem::path goldenDir() {
  const char* override = std::getenv("SNELL_GOLDEN_DIR");
  return override ? std::filesystem::path(override) : std::filesystem::path(SNELL_SOURCE_DIR) / "golden";
}

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

}  // namespace snell::test
