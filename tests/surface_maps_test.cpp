// Normal maps and alpha (trace.h: Normal maps, Alpha): the GPU's trace draws
// them as the CPU reference does, they change the picture where they should
// and only there, and the viewport composite agrees with the trace. A scene
// whose materials use none of them traces a walk with them compiled out
// (kTraceSpecSurface), and draws the same pixels with it.
#include "golden_support.h"
#include "gpu_test.h"

#include "io/image_file.h"
#include "render/one_view.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/scene_builder.h"
#include "scene/view.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>

namespace snell::test {
namespace {

constexpr uint32_t kWidth = 160, kHeight = 120;

// A tangent-space normal map of ripples running across u: the height
// h = a sin(2 pi k u) tilts the normal by -dh/du along +X.
scene::Texture ripples(uint32_t size, double slope) {
  scene::Texture t;
  t.name = "ripples";
  t.width = t.height = size;
  for (uint32_t y = 0; y < size; ++y) {
    for (uint32_t x = 0; x < size; ++x) {
      double u = (x + 0.5) / size;
      glm::dvec3 n = glm::normalize(glm::dvec3(-slope * std::cos(2.0 * 3.14159265358979 * 3.0 * u),
                                               0.4 * slope * std::sin(2.0 * 3.14159265358979 * 2.0 * (y + 0.5) / size), 1.0));
      glm::dvec3 bytes = glm::round((n * 0.5 + 0.5) * 255.0);
      t.rgba.insert(t.rgba.end(), {uint8_t(bytes.x), uint8_t(bytes.y), uint8_t(bytes.z), 255});
    }
  }
  return t;
}

// An 8x8 checker, self-lit, nearest: sharp edges show any displacement.
scene::Texture checker() {
  scene::Texture t;
  t.name = "checker";
  t.width = t.height = 8;
  t.linearFilter = false;
  for (uint32_t i = 0; i < 64; ++i) {
    uint8_t v = ((i % 8) + (i / 8)) % 2 ? 230 : 40;
    t.rgba.insert(t.rgba.end(), {v, uint8_t(v / 2), uint8_t(255 - v), 255});
  }
  return t;
}

// A self-lit checker wall at z = -3 behind whatever the caller adds; lights
// shine from behind it so that it shows only its own light.
scene::Scene wallScene(const std::string& name) {
  scene::Scene s;
  s.source = name;
  s.textures = {checker()};
  scene::Material wall;
  wall.name = "checker wall";
  wall.baseColorFactor = {0, 0, 0, 1};
  wall.emissiveFactor = glm::vec3(1.0f);
  wall.emissiveTexture.texture = 0;
  s.materials = {wall};
  addFlatShape(s, {{-4, -4, -3}, {4, -4, -3}, {4, 4, -3}, {-4, 4, -3}}, {0, 1, 2, 0, 2, 3}, 0);
  return s;
}

// A light from the front and above, for faces that are shaded.
void addKeyLight(scene::Scene& s) {
  scene::Light light;
  light.type = scene::LightType::Directional;
  light.intensity = 2.0f;
  s.lights.push_back(light);
  scene::Node node;
  node.light = int(s.lights.size()) - 1;
  node.rotation = glm::angleAxis(-0.6f, glm::vec3(1, 0, 0)) * glm::angleAxis(0.4f, glm::vec3(0, 1, 0));
  s.nodes.push_back(node);
  s.roots.push_back(int(s.nodes.size()) - 1);
}

int addMaterialTo(scene::Scene& s, const scene::Material& m) {
  s.materials.push_back(m);
  return int(s.materials.size()) - 1;
}

int addTextureTo(scene::Scene& s, const scene::Texture& t) {
  s.textures.push_back(t);
  return int(s.textures.size()) - 1;
}

scene::View frontView(const scene::Scene& s, const scene::Pose& pose) {
  scene::ViewRequest request;
  request.lookAt = scene::LookAt{{0.0, 0.0, 4.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  request.yfov = 0.75;
  return scene::resolveView(s, pose, request);
}

io::Rgb8Image traced(vk::Context& context, const scene::Scene& s) {
  scene::Pose pose = scene::evaluate(s, 0.0);
  render::Renderer renderer(context, s, pose);
  render::FrameSettings settings{kWidth, kHeight, frontView(s, pose), glm::vec3(scene::kDefaultBackground), 8};
  return io::toSrgb8({kWidth, kHeight, render::renderFrame(renderer, pose, settings).rgba});
}

io::Rgb8Image reference(const scene::Scene& s) {
  scene::Pose pose = scene::evaluate(s, 0.0);
  return referenceImage(s, pose, frontView(s, pose), kWidth, kHeight);
}

// The GPU's trace against the reference: pixels whose channels all agree within 1/255.
double agreement(vk::Context& context, const scene::Scene& s, std::string& mismatches) {
  Comparison c = compare(traced(context, s), reference(s));
  mismatches = c.firstMismatches;
  return double(c.withinOne) / double(c.pixels);
}

// Pixels that differ by more than 8/255 in some channel.
double changed(const io::Rgb8Image& a, const io::Rgb8Image& b) {
  size_t count = 0;
  for (size_t i = 0; i < a.rgb.size(); i += 3) {
    bool differs = false;
    for (int c = 0; c < 3; ++c) differs = differs || std::abs(int(a.rgb[i + c]) - int(b.rgb[i + c])) > 8;
    count += differs;
  }
  return double(count) / double(a.rgb.size() / 3);
}

// A slab of glass before the wall, its faces rippled by a normal map (or not).
scene::Scene rippledGlass(bool mapped) {
  scene::Scene s = wallScene(mapped ? "rippled glass" : "flat glass");
  scene::Material glass = scene::clearGlass("glass", 1.5f);
  if (mapped) {
    glass.normalTexture.texture = addTextureTo(s, ripples(64, 0.6));
    glass.normalScale = 0.8f;
  }
  std::vector<glm::vec3> p;
  std::vector<uint32_t> idx;
  scene::addBox({-1.2f, -1.2f, -0.2f}, {1.2f, 1.2f, 0.2f}, p, idx);
  addFlatShape(s, p, idx, addMaterialTo(s, glass));
  return s;
}

// A lit opaque card before the wall, normal-mapped (or not).
scene::Scene rippledCard(bool mapped) {
  scene::Scene s = wallScene(mapped ? "rippled card" : "flat card");
  addKeyLight(s);
  scene::Material card;
  card.name = "card";
  card.baseColorFactor = {0.8f, 0.7f, 0.5f, 1.0f};
  if (mapped) card.normalTexture.texture = addTextureTo(s, ripples(64, 1.2));
  addFlatShape(s, {{-1.5f, -1.2f, 0}, {1.5f, -1.2f, 0}, {1.5f, 1.2f, 0}, {-1.5f, 1.2f, 0}}, {0, 1, 2, 0, 2, 3},
               addMaterialTo(s, card));
  return s;
}

// A card before the wall whose alpha comes from a texture of holes (mask) or
// from its factor (blend); `mode` Opaque draws it whole.
scene::Scene seeThroughCard(scene::AlphaMode mode, float factorAlpha) {
  scene::Scene s = wallScene("see-through card");
  addKeyLight(s);
  scene::Texture holes;
  holes.name = "holes";
  holes.width = holes.height = 4;
  holes.linearFilter = false;
  for (uint32_t i = 0; i < 16; ++i) {
    bool hole = (i % 4 + i / 4) % 2 == 0;
    holes.rgba.insert(holes.rgba.end(), {200, 200, 200, uint8_t(hole ? 0 : 255)});
  }
  scene::Material card;
  card.name = "card";
  card.baseColorFactor = {0.9f, 0.4f, 0.3f, factorAlpha};
  card.baseColorTexture.texture = addTextureTo(s, holes);
  card.alphaMode = mode;
  card.alphaCutoff = 0.5f;
  addFlatShape(s, {{-1.5f, -1.2f, 0}, {1.5f, -1.2f, 0}, {1.5f, 1.2f, 0}, {-1.5f, 1.2f, 0}}, {0, 1, 2, 0, 2, 3},
               addMaterialTo(s, card));
  return s;
}

// The trace's linear colours, for comparisons bit for bit.
std::vector<glm::vec4> tracedLinear(vk::Context& context, const scene::Scene& s) {
  scene::Pose pose = scene::evaluate(s, 0.0);
  render::Renderer renderer(context, s, pose);
  render::FrameSettings settings{kWidth, kHeight, frontView(s, pose), glm::vec3(scene::kDefaultBackground), 8};
  return render::renderFrame(renderer, pose, settings).rgba;
}

uint32_t surfaceOf(vk::Context& context, const scene::Scene& s) {
  return render::uploadScene(context, s, scene::evaluate(s, 0.0)).surface;
}

// `s` with one more material, bound to nothing, that uses every surface
// feature: its trace compiles them all in and must draw the same picture.
scene::Scene withUnusedFeatures(scene::Scene s) {
  scene::Material every;
  every.name = "every feature, on no face";
  int map = addTextureTo(s, ripples(8, 0.5));
  every.baseColorTexture.texture = every.emissiveTexture.texture = map;
  every.normalTexture.texture = every.iorTexture.texture = map;
  every.alphaMode = scene::AlphaMode::Blend;
  addMaterialTo(s, every);
  return s;
}

// The GPU tests of normal maps and alpha against the reference.
class SurfaceMaps : public GpuTest {};

TEST_F(SurfaceMaps, ASceneTracesWithOnlyTheSurfaceFeaturesItsMaterialsUse) {
  // Their opaque faces are single-sided, glTF's default: the walk culls backs.
  const uint32_t oneSided = gpu::kSurfaceSingleSided;
  EXPECT_EQ(surfaceOf(context(), rippledGlass(false)), gpu::kSurfaceTextures | gpu::kSurfaceEmissiveMaps | oneSided);
  EXPECT_EQ(surfaceOf(context(), rippledGlass(true)),
            gpu::kSurfaceTextures | gpu::kSurfaceEmissiveMaps | gpu::kSurfaceNormalMaps | oneSided);
  EXPECT_EQ(surfaceOf(context(), seeThroughCard(scene::AlphaMode::Mask, 1.0f)),
            gpu::kSurfaceTextures | gpu::kSurfaceEmissiveMaps | gpu::kSurfaceAlpha | oneSided);
  scene::Scene plain = rippledGlass(false);
  plain.materials[0].emissiveTexture = {};
  EXPECT_EQ(surfaceOf(context(), plain), oneSided);
  scene::Scene twoSided = plain;
  for (scene::Material& m : twoSided.materials) m.doubleSided = true;
  EXPECT_EQ(surfaceOf(context(), twoSided), 0u);
  EXPECT_EQ(surfaceOf(context(), withUnusedFeatures(plain)), gpu::kSurfaceAll);
}

TEST_F(SurfaceMaps, TheLeanWalkDrawsTheSamePixelsAsTheWalkWithEveryFeature) {
  scene::Scene textured = rippledGlass(false);
  scene::Scene plain = textured;
  plain.materials[0].emissiveTexture = {};
  for (const scene::Scene& s : {textured, plain}) {
    std::vector<glm::vec4> lean = tracedLinear(context(), s);
    std::vector<glm::vec4> full = tracedLinear(context(), withUnusedFeatures(s));
    ASSERT_EQ(lean.size(), full.size());
    size_t differ = 0;
    for (size_t i = 0; i < lean.size(); ++i) differ += lean[i] != full[i];
    EXPECT_EQ(differ, 0u) << s.source << ": pixels that differ between the lean walk and the full one";
  }
}

TEST_F(SurfaceMaps, ANormalMapBendsTheViewThroughGlassAsTheReferenceDoes) {
  std::string mismatches;
  double share = agreement(context(), rippledGlass(true), mismatches);
  std::printf("rippled glass: %.2f%% of pixels within 1/255 of the reference\n", 100.0 * share);
  EXPECT_GE(share, 0.995) << mismatches;
  double moved = changed(traced(context(), rippledGlass(true)), traced(context(), rippledGlass(false)));
  std::printf("the map changed %.1f%% of the pixels\n", 100.0 * moved);
  EXPECT_GT(moved, 0.15) << "the normal map should bend what the glass shows";
}

TEST_F(SurfaceMaps, ANormalMapShadesAnOpaqueFaceAsTheReferenceDoes) {
  std::string mismatches;
  double share = agreement(context(), rippledCard(true), mismatches);
  std::printf("rippled card: %.2f%% of pixels within 1/255 of the reference\n", 100.0 * share);
  EXPECT_GE(share, 0.995) << mismatches;
  double moved = changed(traced(context(), rippledCard(true)), traced(context(), rippledCard(false)));
  EXPECT_GT(moved, 0.15) << "the normal map should change the card's light";
}

TEST_F(SurfaceMaps, MaskedAlphaShowsWhatLiesBehindItsHolesAsTheReferenceDoes) {
  std::string mismatches;
  double share = agreement(context(), seeThroughCard(scene::AlphaMode::Mask, 1.0f), mismatches);
  EXPECT_GE(share, 0.995) << mismatches;
  // Through the holes the wall shows as if the card were not there.
  io::Rgb8Image masked = traced(context(), seeThroughCard(scene::AlphaMode::Mask, 1.0f));
  io::Rgb8Image whole = traced(context(), seeThroughCard(scene::AlphaMode::Opaque, 1.0f));
  scene::Scene wallAlone = wallScene("the wall alone");
  addKeyLight(wallAlone);  // the same highlights on the wall
  io::Rgb8Image wall = traced(context(), wallAlone);
  double holes = 0, holesShowWall = 0;
  for (size_t i = 0; i < masked.rgb.size(); i += 3) {
    bool differsFromCard = false, equalsWall = true;
    for (int c = 0; c < 3; ++c) {
      differsFromCard = differsFromCard || masked.rgb[i + c] != whole.rgb[i + c];
      equalsWall = equalsWall && std::abs(int(masked.rgb[i + c]) - int(wall.rgb[i + c])) <= 1;
    }
    holes += differsFromCard;
    holesShowWall += differsFromCard && equalsWall;
  }
  EXPECT_GT(holes / double(masked.rgb.size() / 3), 0.1) << "the mask should open holes in the card";
  EXPECT_GE(holesShowWall, 0.99 * holes) << "a hole should show the wall unchanged";
}

TEST_F(SurfaceMaps, BlendedAlphaMixesTheFaceWithWhatLiesBehindAsTheReferenceDoes) {
  std::string mismatches;
  double share = agreement(context(), seeThroughCard(scene::AlphaMode::Blend, 0.4f), mismatches);
  EXPECT_GE(share, 0.995) << mismatches;
  io::Rgb8Image blended = traced(context(), seeThroughCard(scene::AlphaMode::Blend, 0.4f));
  io::Rgb8Image whole = traced(context(), seeThroughCard(scene::AlphaMode::Opaque, 0.4f));
  EXPECT_GT(changed(blended, whole), 0.5) << "a blended card should let the wall through everywhere";
}

TEST_F(SurfaceMaps, TheViewportCompositeDrawsAlphaAndNormalMapsAsTheTraceDoes) {
  for (const scene::Scene& s : {seeThroughCard(scene::AlphaMode::Mask, 1.0f), seeThroughCard(scene::AlphaMode::Blend, 0.4f),
                                rippledCard(true)}) {
    scene::Pose pose = scene::evaluate(s, 0.0);
    render::Renderer renderer(context(), s, pose);
    render::FrameSettings settings{kWidth, kHeight, frontView(s, pose), glm::vec3(scene::kDefaultBackground), 8};
    // The viewport's own path: raster, with only the see-through pixels traced.
    render::CompositeFrame frame = render::renderComposite(renderer, pose, settings, {}, false, true);
    Comparison c = compare(io::toSrgb8({kWidth, kHeight, frame.rgba}), traced(context(), s));
    double share = double(c.withinOne) / double(c.pixels);
    std::printf("%s: the viewport matches the trace on %.2f%% of pixels\n", s.source.c_str(), 100.0 * share);
    EXPECT_GE(share, 0.99) << s.source << "\n" << c.firstMismatches;
  }
}

}  // namespace
}  // namespace snell::test
