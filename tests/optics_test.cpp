// Optics beyond the bend, each against its closed form: Fresnel reflectance
// at normal and grazing incidence, Beer-Lambert through a slab, per-channel
// Snell's law with dispersion, and nested media by priority. The GPU and the
// CPU reference are held to the same formulas (shaders/shared/trace.h); the
// golden images (golden_test.cpp) hold them to each other on whole scenes.
#include "golden_support.h"
#include "gpu_test.h"

#include "ref/reference_tracer.h"
#include "render/one_view.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/scene_builder.h"
#include "scene/view.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

namespace snell::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// A uniform environment: every reflected ray sees `colour`.
std::shared_ptr<scene::Environment> uniformEnvironment(glm::vec3 colour) {
  auto env = std::make_shared<scene::Environment>();
  env->source = "uniform";
  env->width = env->height = 1;
  env->texels = {colour};
  return env;
}

/// The closed form: unpolarised reflectance of light from n1 into n2 at incidence theta.
double closedFormReflectance(double n1, double n2, double theta) {
  double ci = std::cos(theta), st = n1 / n2 * std::sin(theta);
  if (st >= 1.0) return 1.0;
  double ct = std::sqrt(1.0 - st * st);
  double rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct), rp = (n1 * ct - n2 * ci) / (n1 * ct + n2 * ci);
  return 0.5 * (rs * rs + rp * rp);
}

/// A light shining from behind everything the tests aim at (+Z towards -Z is
/// the rays' way; this one shines along +Z): no face the rays see is lit, so
/// no highlight or diffuse term mixes into the numbers.
void addBackLight(scene::Scene& s) {
  scene::Light light;
  light.type = scene::LightType::Directional;
  s.lights.push_back(light);
  scene::Node node;
  node.light = int(s.lights.size()) - 1;
  node.rotation = glm::angleAxis(float(kPi), glm::vec3(0, 1, 0));  // -Z turned to +Z
  s.nodes.push_back(node);
  s.roots.push_back(int(s.nodes.size()) - 1);
}

/// A wide glass slab z in [-1, 1] (x, y in [-50, 50]).
scene::Scene slabScene(scene::Material glass) {
  scene::Scene s;
  s.source = "slab";
  s.materials = {glass};
  std::vector<glm::vec3> p;
  std::vector<uint32_t> idx;
  scene::addBox({-50, -50, -1}, {50, 50, 1}, p, idx);
  addFlatShape(s, p, idx, 0);
  addBackLight(s);
  return s;
}

scene::Material glassOf(float ior) {
  scene::Material glass = scene::clearGlass("glass", ior);
  return glass;
}

struct Traced {
  std::vector<glm::vec3> gpu;
  ref::ReferenceImage reference;
};

/// Traces `rays` (one pixel each) on the GPU and in the reference.
Traced traceRays(vk::Context& context, const scene::Scene& s, const std::vector<scene::Ray>& rays,
                 const scene::Optics& optics, glm::vec3 background) {
  scene::Pose pose = scene::evaluate(s, 0.0);
  scene::View view = scene::resolveView(s, pose, {});
  uint32_t width = uint32_t(rays.size());
  render::Renderer renderer(context, s, pose);
  render::FrameSettings settings{width, 1, view, background, gpu::kDefaultMaxInterfaces};
  settings.rays = rays;
  settings.optics = optics;
  render::RenderedFrame frame = render::renderFrame(renderer, pose, settings);
  ref::ReferenceSettings reference;
  reference.width = width;
  reference.height = 1;
  reference.view = view;
  reference.background = glm::dvec3(background);
  reference.rays = rays;
  reference.optics = optics;
  Traced t;
  for (const glm::vec4& c : frame.rgba) t.gpu.emplace_back(c);
  t.reference = ref::renderReference(s, pose, reference);
  return t;
}

class Optics : public GpuTest {};

TEST_F(Optics, FresnelReflectanceMatchesTheClosedFormFromNormalToGrazingIncidence) {
  // A white environment, a black background: what comes back is R alone (the
  // transmitted ray leaves through the back face into black).
  scene::Scene s = slabScene(glassOf(1.5f));
  scene::Optics optics;
  optics.environment = uniformEnvironment(glm::vec3(1.0f));
  const double angles[] = {0.0, 30.0, 60.0, 80.0, 89.0};
  std::vector<scene::Ray> rays;
  for (double degrees : angles) {
    double theta = degrees * kPi / 180.0;
    glm::dvec3 d(std::sin(theta), 0.0, -std::cos(theta));
    rays.push_back({glm::dvec3(0.0, 0.0, 1.0) - 10.0 * d, d});
  }
  Traced t = traceRays(context(), s, rays, optics, glm::vec3(0.0f));
  for (size_t i = 0; i < rays.size(); ++i) {
    double want = closedFormReflectance(1.0, 1.5, angles[i] * kPi / 180.0);
    SCOPED_TRACE("incidence " + std::to_string(angles[i]) + " degrees, R = " + std::to_string(want));
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(t.reference.color[i][c], want, 1e-12);
      EXPECT_NEAR(t.gpu[i][c], want, 2e-3 * std::max(1.0, want * 2.0));  // float, then a half-float image
    }
    EXPECT_LT(t.reference.energyError[i], 1e-6) << "R + T = 1 at every interface";
  }
  EXPECT_NEAR(closedFormReflectance(1.0, 1.5, 0.0), 0.04, 1e-15);  // the textbook value
}

TEST_F(Optics, TotalInternalReflectionKeepsAllTheLight) {
  // From inside the slab past the critical angle (41.8 degrees at 1.5): the
  // ray reflects between the faces until the interface limit, with no loss.
  scene::Scene s = slabScene(glassOf(1.5f));
  double theta = 60.0 * kPi / 180.0;
  glm::dvec3 d(std::sin(theta), 0.0, -std::cos(theta));
  Traced t = traceRays(context(), s, {{glm::dvec3(0.0, 0.0, 0.5), d}}, scene::Optics{}, glm::vec3(1.0f));
  EXPECT_EQ(t.reference.outcome[0], gpu::kOutcomeInterfaceLimit);
  // The limit ends the ray on the background (white): everything is still there.
  EXPECT_NEAR(t.reference.color[0].r, 1.0, 1e-12);
  EXPECT_NEAR(t.gpu[0].r, 1.0f, 1e-3f);
}

// A slab of glass 2 units thick that keeps (0.5, 0.8, 0.9) of the light over `distance`.
scene::Material tintedGlass(float distance) {
  scene::Material glass = glassOf(1.5f);
  glass.thickness = 2.0f;
  glass.attenuationColor = {0.5f, 0.8f, 0.9f};
  glass.attenuationDistance = distance;
  return glass;
}

TEST_F(Optics, BeerLambertAttenuatesBySlabThickness) {
  const scene::Material glass = tintedGlass(1.0f);
  scene::Scene s = slabScene(glass);
  scene::Optics optics;
  optics.fresnel = false;  // the volume alone
  Traced t = traceRays(context(), s, {{{0.0, 0.0, 5.0}, {0.0, 0.0, -1.0}}}, optics, glm::vec3(1.0f));
  for (int c = 0; c < 3; ++c) {
    double want = std::pow(double(glass.attenuationColor[c]), 2.0 / 1.0);  // 2 units inside, attenuation distance 1
    EXPECT_NEAR(t.reference.color[0][c], want, 1e-6);
    EXPECT_NEAR(t.gpu[0][c], want, 1e-3);
  }
}

TEST_F(Optics, BeerLambertAndFresnelMultiply) {
  const scene::Material glass = tintedGlass(4.0f);
  scene::Scene s = slabScene(glass);
  scene::Optics optics;
  optics.environment = uniformEnvironment(glm::vec3(0.0f));  // the reflection sees black
  Traced t = traceRays(context(), s, {{{0.0, 0.0, 5.0}, {0.0, 0.0, -1.0}}}, optics, glm::vec3(1.0f));
  double transmit = 1.0 - closedFormReflectance(1.0, 1.5, 0.0);
  for (int c = 0; c < 3; ++c) {
    double want = transmit * transmit * std::pow(double(glass.attenuationColor[c]), 2.0 / 4.0);
    EXPECT_NEAR(t.reference.color[0][c], want, 1e-6);
    EXPECT_NEAR(t.gpu[0][c], want, 1e-3);
  }
}

TEST_F(Optics, ThinWalledGlassDoesNotAttenuate) {
  scene::Material glass = glassOf(1.5f);
  glass.thickness = 0.0f;  // glTF: thin-walled
  glass.attenuationColor = {0.5f, 0.5f, 0.5f};
  glass.attenuationDistance = 1.0f;
  scene::Optics optics;
  optics.fresnel = false;
  Traced t = traceRays(context(), slabScene(glass), {{{0.0, 0.0, 5.0}, {0.0, 0.0, -1.0}}}, optics, glm::vec3(1.0f));
  EXPECT_NEAR(t.reference.color[0].g, 1.0, 1e-12);
  EXPECT_NEAR(t.gpu[0].g, 1.0f, 1e-3f);
}

TEST_F(Optics, DispersionBendsEachChannelBySnellsLawWithItsOwnIor) {
  // A ray enters a glass block's top face at 40 degrees and lands on a
  // self-lit floor inside it whose brightness is (x + 1) / 2: each channel
  // reads where its own refracted ray landed.
  scene::Scene s;
  s.source = "dispersive block";
  scene::Material glass = glassOf(1.5f);
  glass.dispersion = 5.0f;  // Abbe number 4: far more than any glass, so the spread is measurable
  scene::Texture ramp;  // texel centres at u = 0.25 and 0.75, linear between (clamped)
  ramp.width = 2;
  ramp.height = 1;
  ramp.rgba = {0, 0, 0, 255, 255, 255, 255, 255};
  ramp.repeatS = ramp.repeatT = false;
  s.textures = {ramp};
  scene::Material floor;
  floor.name = "ramp floor";
  floor.baseColorFactor = {0, 0, 0, 1};
  floor.emissiveFactor = glm::vec3(1.0f);
  floor.emissiveTexture.texture = 0;
  floor.emissiveTexture.transform = glm::mat3(1.0f);  // u' = u / 2 + 0.25, with u = x / 2 + 0.5 from the shape
  floor.emissiveTexture.transform[0][0] = 0.5f;
  floor.emissiveTexture.transform[2][0] = 0.25f;
  s.materials = {glass, floor};
  std::vector<glm::vec3> p;
  std::vector<uint32_t> idx;
  scene::addBox({-5, -1, -5}, {5, 1, 5}, p, idx);
  addFlatShape(s, p, idx, 0);
  // The floor at y = 0, facing up, texture u from x.
  addFlatShape(s, {{-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}}, {0, 1, 2, 0, 2, 3}, 1);
  scene::Light light;  // from below: the floor faces away from it
  light.type = scene::LightType::Directional;
  s.lights = {light};
  scene::Node lightNode;
  lightNode.light = 0;
  lightNode.rotation = glm::angleAxis(float(kPi / 2), glm::vec3(1, 0, 0));  // shines along +Y
  s.nodes.push_back(lightNode);
  s.roots.push_back(int(s.nodes.size()) - 1);

  double theta = 40.0 * kPi / 180.0;
  glm::dvec3 d(std::sin(theta), -std::cos(theta), 0.0);
  scene::Optics optics;
  optics.fresnel = false;  // T = 1: the floor's brightness is all that arrives
  Traced t = traceRays(context(), s, {{glm::dvec3(0.0, 1.0, 0.0) - 3.0 * d, d}}, optics, glm::vec3(0.0f));
  double spread = 0.025 * 5.0 * (1.5 - 1.0);
  const double iors[3] = {1.5 - spread, 1.5, 1.5 + spread};
  double landed[3];
  for (int c = 0; c < 3; ++c) {
    double refracted = std::asin(std::sin(theta) / iors[c]);
    landed[c] = std::tan(refracted);  // x on the floor, one unit below the top face
    double want = (landed[c] + 1.0) / 2.0;
    SCOPED_TRACE("channel " + std::to_string(c) + ", IOR " + std::to_string(iors[c]));
    EXPECT_NEAR(t.reference.color[0][c], want, 1e-9);
    EXPECT_NEAR(t.gpu[0][c], want, 1.5e-3);
  }
  EXPECT_GT(landed[0] - landed[2], 0.03) << "red bends least, blue most";
}

TEST_F(Optics, ALowerPriorityMediumInsideAHigherOneDoesNotBend) {
  // A block of priority 1 wholly containing a denser block of priority 0: the
  // inner block's faces are not boundaries, so rays see the outer block alone.
  auto blocks = [](bool inner) {
    scene::Scene s;
    s.source = "nested blocks";
    scene::Material outer = glassOf(1.5f), dense = glassOf(2.0f);
    outer.priority = 1;
    s.materials = {outer, dense};
    std::vector<glm::vec3> p;
    std::vector<uint32_t> idx;
    scene::addBox({-2, -2, -2}, {2, 2, 2}, p, idx);
    addFlatShape(s, p, idx, 0);
    if (inner) {
      std::vector<glm::vec3> q;
      std::vector<uint32_t> qi;
      scene::addBox({-1, -1, -1}, {1, 1, 1}, q, qi);
      addFlatShape(s, q, qi, 1);
    }
    addBackLight(s);
    return s;
  };
  std::vector<scene::Ray> rays;
  for (int i = 0; i < 5; ++i) {
    glm::dvec3 d = glm::normalize(glm::dvec3(0.1 * i, 0.05 * i, -1.0));
    rays.push_back({glm::dvec3(-0.3, 0.2, 6.0), d});
  }
  scene::Optics optics;
  Traced nested = traceRays(context(), blocks(true), rays, optics, glm::vec3(0.3f, 0.6f, 0.9f));
  Traced alone = traceRays(context(), blocks(false), rays, optics, glm::vec3(0.3f, 0.6f, 0.9f));
  for (size_t i = 0; i < rays.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(nested.reference.color[i][c], alone.reference.color[i][c], 1e-9) << "ray " << i;
      EXPECT_NEAR(nested.gpu[i][c], alone.gpu[i][c], 1e-3) << "ray " << i;
    }
  }
  // The straight ray crosses the inner block's two faces without bending there.
  EXPECT_EQ(nested.reference.interfaces[0], alone.reference.interfaces[0] + 2);
}

TEST_F(Optics, EqualPrioritiesHandOverBetweenMediaAtTheirOwnIors) {
  // Air into a block of 1.5 that touches nothing: at normal incidence R is the
  // air/glass value; inside a block of 1.5 a nested block of 1.5 (equal
  // priority) is no change of medium at all: R = 0 there.
  scene::Scene s;
  s.source = "same glass nested";
  s.materials = {glassOf(1.5f), glassOf(1.5f)};
  std::vector<glm::vec3> p, q;
  std::vector<uint32_t> idx, qi;
  scene::addBox({-2, -2, -2}, {2, 2, 2}, p, idx);
  addFlatShape(s, p, idx, 0);
  scene::addBox({-1, -1, -1}, {1, 1, 1}, q, qi);
  addFlatShape(s, q, qi, 1);
  addBackLight(s);
  scene::Optics optics;
  optics.environment = uniformEnvironment(glm::vec3(0.0f));
  Traced t = traceRays(context(), s, {{{0.0, 0.0, 6.0}, {0.0, 0.0, -1.0}}}, optics, glm::vec3(1.0f));
  double transmit = 1.0 - closedFormReflectance(1.0, 1.5, 0.0);
  // Four faces of block 0 and 1 crossed; only the outer two change the medium.
  EXPECT_NEAR(t.reference.color[0].r, transmit * transmit, 1e-9);
  EXPECT_NEAR(t.gpu[0].r, transmit * transmit, 1e-3);
}

}  // namespace
}  // namespace snell::test
