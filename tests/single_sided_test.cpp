// Single-sided faces (glTF's and USD's doubleSided false, glass apart): every
// ray passes their backs, as a rasterising viewer culls them, and the
// viewport's raster does the same. The GPU is held to the reference in each case.
#include "gpu_test.h"

#include "io/image_file.h"
#include "ref/reference_tracer.h"
#include "render/one_view.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/scene_builder.h"
#include "scene/view.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

namespace snell::test {
namespace {

constexpr uint32_t kSize = 48;
const glm::vec3 kRed{0.9f, 0.1f, 0.1f}, kGreen{0.1f, 0.8f, 0.1f}, kBlue{0.1f, 0.2f, 0.9f};

int selfLit(scene::Scene& s, const char* name, glm::vec3 colour, bool doubleSided) {
  scene::Material m;
  m.name = name;
  m.baseColorFactor = {0, 0, 0, 1};
  m.emissiveFactor = colour;
  m.doubleSided = doubleSided;
  return scene::addMaterial(s, m);
}

// A unit quad in z = 0 facing +z (red, single-sided unless said), between a
// green wall at z = -2 facing +z and a blue one at z = 2 facing -z (both
// double-sided), placed by `world`.
scene::Scene quadBetweenWalls(bool doubleSided, const glm::mat4& world = glm::mat4(1.0f)) {
  scene::Scene s;
  s.source = "a quad between walls";
  scene::Shape quad;
  quad.name = "quad";
  scene::addQuad(quad, {-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {0.5f, 0.5f, 0}, {-0.5f, 0.5f, 0});
  quad.material = selfLit(s, "red", kRed, doubleSided);
  scene::addRootShape(s, quad, world);
  scene::Shape green, blue;
  green.name = "green wall";
  scene::addQuad(green, {-4, -4, -2}, {4, -4, -2}, {4, 4, -2}, {-4, 4, -2});
  green.material = selfLit(s, "green", kGreen, true);
  scene::addRootShape(s, green);
  blue.name = "blue wall";
  scene::addQuad(blue, {-4, -4, 2}, {-4, 4, 2}, {4, 4, 2}, {4, -4, 2});
  blue.material = selfLit(s, "blue", kBlue, true);
  scene::addRootShape(s, blue);
  return s;
}

struct Seen {
  glm::vec3 gpu, reference, composite;
};

// The middle pixel of the trace, the reference and the viewport from z (looking along -z, or +z from below 0).
Seen middleFrom(vk::Context& context, const scene::Scene& s, double z) {
  scene::Pose pose = scene::evaluate(s, 0.0);
  scene::ViewRequest request;
  request.lookAt = scene::LookAt{{0.0, 0.0, z}, {0.0, 0.0, z > 0 ? -10.0 : 10.0}, {0.0, 1.0, 0.0}};
  request.yfov = 0.5;
  scene::View view = scene::resolveView(s, pose, request);
  render::FrameSettings settings{kSize, kSize, view, glm::vec3(0.0f), 8};
  render::Renderer renderer(context, s, pose);
  render::RenderedFrame frame = render::renderFrame(renderer, pose, settings);
  render::CompositeFrame composite = render::renderComposite(renderer, pose, settings, render::RasterOptions{});
  ref::ReferenceSettings rs;
  rs.width = rs.height = kSize;
  rs.view = view;
  ref::ReferenceImage reference = ref::renderReference(s, pose, rs);
  const size_t middle = size_t(kSize / 2) * kSize + kSize / 2;
  return {glm::vec3(frame.rgba[middle]), glm::vec3(reference.color[middle]), glm::vec3(composite.rgba[middle])};
}

// Which of the three self-lit colours a pixel shows (the headlight adds to each alike).
int hue(glm::vec3 c) { return c.r > c.g && c.r > c.b ? 0 : c.g > c.b ? 1 : 2; }

void expectAll(const Seen& seen, glm::vec3 colour, const char* what) {
  for (const glm::vec3& c : {seen.gpu, seen.reference, seen.composite}) {
    EXPECT_EQ(hue(c), hue(colour)) << what << ": got (" << c.r << ", " << c.g << ", " << c.b << ")";
  }
  EXPECT_LT(glm::length(seen.gpu - seen.reference), 0.01f) << what << ": the trace against the reference";
  EXPECT_LT(glm::length(seen.composite - seen.gpu), 0.01f) << what << ": the viewport against the trace";
}

class SingleSided : public GpuTest {};

TEST_F(SingleSided, AFaceSeenFromBehindIsPassedByTheCameraRayAndTheRaster) {
  scene::Scene s = quadBetweenWalls(false);
  expectAll(middleFrom(context(), s, 1.5), kRed, "its front");
  expectAll(middleFrom(context(), s, -1.5), kBlue, "its back: the blue wall beyond it");
}

TEST_F(SingleSided, ADoubleSidedFaceIsSeenFromBothSides) {
  scene::Scene s = quadBetweenWalls(true);
  expectAll(middleFrom(context(), s, 1.5), kRed, "its front");
  expectAll(middleFrom(context(), s, -1.5), kRed, "its back");
}

TEST_F(SingleSided, AMirroredInstanceKeepsItsFront) {
  // Mirrored in x the quad's corners run clockwise seen from +z, and it still
  // faces +z, where its normal points: glTF makes a mirrored face's front
  // clockwise, so a mirrored mesh is not drawn inside out.
  scene::Scene s = quadBetweenWalls(false, glm::scale(glm::mat4(1.0f), glm::vec3(-1.0f, 1.0f, 1.0f)));
  expectAll(middleFrom(context(), s, 1.5), kRed, "its front");
  expectAll(middleFrom(context(), s, -1.5), kBlue, "its back: the blue wall beyond it");
}

TEST_F(SingleSided, AMirroredGlassSphereRefractsAsTheSphereItMirrors) {
  // A sphere mirrored in x is the same sphere: its inside stays inside, in
  // the trace and in the reference alike.
  auto scene = [](bool mirrored) {
    scene::Scene s = quadBetweenWalls(true);
    scene::Shape sphere = scene::uvSphere(24, 0.4f);
    sphere.material = scene::addMaterial(s, scene::clearGlass("glass", 1.5f));
    glm::mat4 world = glm::translate(glm::mat4(1.0f), glm::vec3(0.1f, 0.05f, 0.8f));
    if (mirrored) world = glm::scale(world, glm::vec3(-1.0f, 1.0f, 1.0f));
    scene::addRootShape(s, sphere, world);
    return s;
  };
  Seen plain = middleFrom(context(), scene(false), 1.5), mirrored = middleFrom(context(), scene(true), 1.5);
  EXPECT_LT(glm::length(mirrored.gpu - plain.gpu), 0.01f);
  EXPECT_LT(glm::length(mirrored.reference - plain.reference), 0.01f);
  EXPECT_LT(glm::length(mirrored.gpu - mirrored.reference), 0.01f);
}

TEST_F(SingleSided, ARayThroughGlassPassesABackFaceAsARayWithoutGlassDoes) {
  // A pane of glass of IOR 1 before the quad's back: nothing bends, so what
  // lies behind is what no pane would show.
  scene::Scene s = quadBetweenWalls(false);
  scene::Material glass = scene::clearGlass("glass", 1.0f);
  scene::Shape pane;
  pane.name = "pane";
  scene::addQuad(pane, {-1, -1, -1}, {-1, 1, -1}, {1, 1, -1}, {1, -1, -1});
  pane.material = scene::addMaterial(s, glass);
  scene::addRootShape(s, pane);
  Seen seen = middleFrom(context(), s, -1.5);
  expectAll(seen, kBlue, "the blue wall beyond its back, through glass");
}

}  // namespace
}  // namespace snell::test
