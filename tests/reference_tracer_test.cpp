// The CPU reference tracer against answers worked out by hand from the
// contract in shaders/shared/trace.h, on scenes built in code; and the
// binned SAH cost against trees priced by hand.
#include "ref/reference_tracer.h"
#include "ref/sah_bvh.h"
#include "scene/evaluate.h"
#include "scene/procedural_eye.h"
#include "scene/view.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace snell::test {
namespace {

constexpr double kPi = 3.14159265358979323846;
const double kAmbient = double(gpu::kAmbient);
const double kSpecular = double(gpu::kSpecular);
const double kShininess = double(gpu::kShininess);
const double kHeadlight = double(gpu::kHeadlight);

double srgbToLinear(int byte) {
  double c = byte / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

/// Scenes of quads and lights, every node a root; the pose's items come out
/// in the order the quads were added.
struct SceneBuilder {
  scene::Scene s;

  int material(const scene::Material& m) {
    s.materials.push_back(m);
    return int(s.materials.size() - 1);
  }
  int texture(const scene::Texture& t) {
    s.textures.push_back(t);
    return int(s.textures.size() - 1);
  }
  int node(scene::Node n) {
    s.nodes.push_back(std::move(n));
    int index = int(s.nodes.size() - 1);
    s.roots.push_back(index);
    return index;
  }
  /// Corners counter-clockwise seen from the front; triangles (0 1 2), (0 2 3).
  int quad(const std::array<glm::vec3, 4>& corners, int material,
           const std::array<glm::vec2, 4>& uv = {glm::vec2(0, 1), glm::vec2(1, 1), glm::vec2(1, 0), glm::vec2(0, 0)}) {
    scene::Shape shape;
    shape.material = material;
    glm::vec3 normal = glm::normalize(glm::cross(corners[1] - corners[0], corners[2] - corners[0]));
    for (int k = 0; k < 4; ++k) {
      shape.positions.push_back(corners[size_t(k)]);
      shape.normals.push_back(normal);
      shape.texcoords0.push_back(uv[size_t(k)]);
    }
    shape.indices = {0, 1, 2, 0, 2, 3};
    return addShape(std::move(shape));
  }
  int addShape(scene::Shape shape) {
    shape.mesh = int(s.meshes.size());
    s.shapes.push_back(std::move(shape));
    scene::Mesh mesh;
    mesh.shapes = {int(s.shapes.size() - 1)};
    mesh.weights.assign(s.shapes.back().targets.size(), 0.0f);
    s.meshes.push_back(mesh);
    scene::Node n;
    n.mesh = int(s.meshes.size() - 1);
    return node(n);
  }
  /// An axis-aligned quad in the plane z = `z`, facing +z (or -z).
  int quadAtZ(float z, float x0, float x1, float y0, float y1, int material, bool facingPlusZ = true) {
    std::array<glm::vec3, 4> c = {glm::vec3(x0, y0, z), glm::vec3(x1, y0, z), glm::vec3(x1, y1, z), glm::vec3(x0, y1, z)};
    if (!facingPlusZ) std::swap(c[1], c[3]);
    return quad(c, material);
  }
  int light(const scene::Light& l, glm::vec3 position, glm::vec3 shines) {
    s.lights.push_back(l);
    scene::Node n;
    n.light = int(s.lights.size() - 1);
    // glTF lights shine down their node's -Z. A matrix with that column
    // exactly -shines (unnormalised: the tracer normalises it) keeps float
    // rotations from blurring the hand-computed answers.
    glm::vec3 back = -shines;
    glm::vec3 side = glm::cross(back, std::abs(shines.y) > 0.9f * glm::length(shines) ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0));
    n.matrix = glm::mat4(glm::vec4(side, 0.0f), glm::vec4(glm::cross(back, side), 0.0f), glm::vec4(back, 0.0f),
                         glm::vec4(position, 1.0f));
    return node(n);
  }
  /// A light of zero intensity: the scene has a light, so no headlight, and nothing is lit.
  int darkness() {
    scene::Light l;
    l.type = scene::LightType::Directional;
    l.intensity = 0.0f;
    return light(l, glm::vec3(0.0f), glm::vec3(0, 0, -1));
  }
};

scene::Material opaque(glm::vec3 base) {
  scene::Material m;
  m.baseColorFactor = glm::vec4(base, 1.0f);
  return m;
}

scene::Material refractive(float ior, glm::vec3 tint = glm::vec3(1.0f)) {
  scene::Material m;
  m.baseColorFactor = glm::vec4(tint, 1.0f);
  m.transmission = 1.0f;
  m.ior = ior;
  return m;
}

/// Black, lit by nothing but its emissive texture: its colour is the texture.
scene::Material emissiveOnly(int texture) {
  scene::Material m;
  m.baseColorFactor = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  m.emissiveFactor = glm::vec3(1.0f);
  m.emissiveTexture.texture = texture;
  return m;
}

/// A texture of width x height RGBA bytes, red = green = blue = the value given per texel.
scene::Texture greyTexture(uint32_t width, uint32_t height, std::vector<uint8_t> values) {
  scene::Texture t;
  t.width = width;
  t.height = height;
  for (uint8_t v : values) t.rgba.insert(t.rgba.end(), {v, v, v, 255});
  return t;
}

scene::View orthographic(glm::dvec3 eye, glm::dvec3 forward, double halfHeight = 1.0) {
  scene::View v;
  v.eye = eye;
  v.forward = glm::normalize(forward);
  glm::dvec3 up = std::abs(v.forward.y) > 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  v.right = glm::normalize(glm::cross(v.forward, up));
  v.up = glm::cross(v.right, v.forward);
  v.orthographic = true;
  v.halfHeight = halfHeight;
  return v;
}

ref::ReferenceImage render(const scene::Scene& s, const scene::View& view, uint32_t width, uint32_t height,
                           uint32_t maxInterfaces = gpu::kDefaultMaxInterfaces) {
  ref::ReferenceSettings settings;
  settings.width = width;
  settings.height = height;
  settings.view = view;
  settings.maxInterfaces = maxInterfaces;
  // These tests read where rays went from the colour they bring back, so
  // Fresnel's split of the light is off here (tests/optics_test.cpp tests it).
  settings.optics.fresnel = false;
  return ref::renderReference(s, scene::evaluate(s, 0.0), settings);
}

/// The centre pixel of a 3x3 perspective picture looks straight down the view's forward axis.
glm::dvec3 centre(const ref::ReferenceImage& image) { return image.color[image.index(1, 1)]; }

void expectColorNear(const glm::dvec3& got, const glm::dvec3& expected, double tolerance = 1e-12) {
  EXPECT_NEAR(got.r, expected.r, tolerance);
  EXPECT_NEAR(got.g, expected.g, tolerance);
  EXPECT_NEAR(got.b, expected.b, tolerance);
}

TEST(ReferenceTracer, LitOpaqueQuadGivesTheHandComputedPhongValue) {
  SceneBuilder b;
  scene::Material m = opaque({0.8f, 0.5f, 0.2f});
  m.emissiveFactor = {0.1f, 0.0f, 0.05f};
  // Off-centre so the pixel's ray does not land on the quad's diagonal.
  b.quadAtZ(-1.0f, -1.0f, 1.5f, -1.0f, 1.0f, b.material(m));
  scene::Light sun;
  sun.type = scene::LightType::Directional;
  sun.color = {1.0f, 0.5f, 1.0f};
  sun.intensity = 2.0f;
  b.light(sun, glm::vec3(0.0f), glm::vec3(0.0f, -1.0f, -1.0f));  // 45 degrees off the quad's normal

  ref::ReferenceImage image = render(b.s, scene::View{}, 3, 3);
  // N = V = +z, L at 45 degrees, H halfway: N.L = cos 45, N.H = cos 22.5.
  glm::dvec3 base(0.8f, 0.5f, 0.2f), emissive(0.1f, 0.0f, 0.05f), e = glm::dvec3(1.0, 0.5, 1.0) * 2.0;
  glm::dvec3 expected = emissive + kAmbient * base +
                        e * std::cos(kPi / 4) * (base / kPi + kSpecular * std::pow(std::cos(kPi / 8), kShininess));
  expectColorNear(centre(image), expected);
  EXPECT_EQ(image.outcome[image.index(1, 1)], gpu::kOutcomeOpaque);
  EXPECT_NEAR(image.distance[image.index(1, 1)], 1.0, 1e-15);
}

TEST(ReferenceTracer, PointLightFallsOffWithInverseSquareAndRangeWindow) {
  SceneBuilder b;
  b.quadAtZ(-1.0f, -1.0f, 1.5f, -1.0f, 1.0f, b.material(opaque({0.5f, 0.5f, 0.5f})));
  scene::Light bulb;
  bulb.type = scene::LightType::Point;
  bulb.intensity = 3.0f;
  bulb.range = 1.0f;
  b.light(bulb, glm::vec3(0.0f, 0.0f, -0.5f), glm::vec3(0, 0, -1));  // 0.5 in front of the quad's centre

  ref::ReferenceImage image = render(b.s, scene::View{}, 3, 3);
  double window = (1.0 - std::pow(0.5, 4)) * (1.0 - std::pow(0.5, 4));
  double e = 3.0 / 0.25 * window;
  glm::dvec3 base(0.5f);
  expectColorNear(centre(image), kAmbient * base + e * (base / kPi + kSpecular));  // N = L = H = V
}

TEST(ReferenceTracer, SpotLightConeScalesBySquaredSmoothFactor) {
  SceneBuilder b;
  b.quadAtZ(-1.0f, -1.0f, 1.5f, -1.0f, 1.0f, b.material(opaque({0.5f, 0.5f, 0.5f})));
  const double angle = 0.3;  // between the spot's axis and the way to the shaded point
  scene::Light spot;
  spot.type = scene::LightType::Spot;
  spot.intensity = 2.0f;
  spot.innerConeAngle = 0.1f;
  spot.outerConeAngle = 0.5f;
  glm::vec3 position(float(0.5 * std::tan(angle)), 0.0f, -0.5f);
  b.light(spot, position, glm::vec3(0, 0, -1));

  ref::ReferenceImage image = render(b.s, scene::View{}, 3, 3);
  glm::dvec3 toLight = glm::dvec3(position) - glm::dvec3(0, 0, -1);
  double distance = glm::length(toLight);
  glm::dvec3 l = toLight / distance, v(0, 0, 1), h = glm::normalize(l + v);
  // The spot points down -z, so the cosine of the angle off its axis is l.z.
  const double cosInner = std::cos(double(0.1f)), cosOuter = std::cos(double(0.5f));
  double s = (l.z - cosOuter) / (cosInner - cosOuter);
  double e = 2.0 / (distance * distance) * s * s;
  glm::dvec3 base(0.5f);
  glm::dvec3 expected = kAmbient * base + e * l.z * (base / kPi + kSpecular * std::pow(h.z, kShininess));
  expectColorNear(centre(image), expected);
  EXPECT_GT(s, 0.0);
  EXPECT_LT(s, 1.0);
}

TEST(ReferenceTracer, HeadlightLightsASceneWithoutLightNodes) {
  SceneBuilder b;
  b.quadAtZ(-1.0f, -1.0f, 1.5f, -1.0f, 1.0f, b.material(opaque({0.5f, 0.25f, 1.0f})));
  scene::Light unplaced;  // in the list, but no node carries it
  b.s.lights.push_back(unplaced);
  glm::dvec3 base(0.5f, 0.25f, 1.0f);
  // The headlight shines along the view: N = L = H = V.
  expectColorNear(centre(render(b.s, scene::View{}, 3, 3)), kAmbient * base + kHeadlight * (base / kPi + kSpecular));

  b.darkness();  // a placed light, of zero intensity, turns the headlight off
  expectColorNear(centre(render(b.s, scene::View{}, 3, 3)), kAmbient * base);
}

TEST(ReferenceTracer, MissingMaterialIsWhiteAndOpaque) {
  SceneBuilder b;
  b.quadAtZ(-1.0f, -1.0f, 1.5f, -1.0f, 1.0f, -1);
  b.darkness();
  ref::ReferenceImage image = render(b.s, scene::View{}, 3, 3);
  expectColorNear(centre(image), glm::dvec3(kAmbient));
  EXPECT_EQ(image.outcome[image.index(1, 1)], gpu::kOutcomeOpaque);
}

TEST(ReferenceTracer, BaseColourIsFactorTimesDecodedTexture) {
  SceneBuilder b;
  scene::Texture t;
  t.width = t.height = 1;
  t.rgba = {255, 128, 0, 255};
  scene::Material m = opaque({0.5f, 1.0f, 1.0f});
  m.baseColorTexture.texture = b.texture(t);
  b.quadAtZ(-1.0f, -1.0f, 1.5f, -1.0f, 1.0f, b.material(m));
  b.darkness();
  expectColorNear(centre(render(b.s, scene::View{}, 3, 3)), kAmbient * glm::dvec3(0.5, srgbToLinear(128), 0.0));
}

/// A backdrop in the plane z = `z`, facing +z, whose colour tells where a
/// ray hit it: position() recovers x anywhere in [-5, 5].
struct GradientBackdrop {
  static constexpr float kHalfWidth = 10.0f;
  /// Emissive-only, texture 2x1 black to white, clamped, bilinear: for u in
  /// [0.25, 0.75] the colour is 2u - 0.5, and u = (x + W) / 2W.
  static int add(SceneBuilder& b, float z) {
    scene::Texture t = greyTexture(2, 1, {0, 255});
    t.repeatS = t.repeatT = false;
    int material = b.material(emissiveOnly(b.texture(t)));
    std::array<glm::vec3, 4> corners = {glm::vec3(-kHalfWidth, -kHalfWidth, z), glm::vec3(kHalfWidth, -kHalfWidth, z),
                                        glm::vec3(kHalfWidth, kHalfWidth, z), glm::vec3(-kHalfWidth, kHalfWidth, z)};
    return b.quad(corners, material, {glm::vec2(0, 0.5f), glm::vec2(1, 0.5f), glm::vec2(1, 0.5f), glm::vec2(0, 0.5f)});
  }
  static double position(const glm::dvec3& color) {
    double u = (color.r + 0.5) / 2.0;
    return 2.0 * kHalfWidth * u - kHalfWidth;
  }
};

TEST(ReferenceTracer, SlabShiftsARayParallelToItselfAsSnellsLawSays) {
  const double theta = 0.5, ior = 1.5, thickness = 0.5;
  // A slab between z = 0 and z = -thickness, faces facing out; the backdrop
  // at z = -depth; the ray leaves (0, 0, 1) at theta from the slab's normal.
  auto hitX = [&](float depth, ref::ReferenceImage* out) {
    SceneBuilder b;
    int glass = b.material(refractive(float(ior)));
    b.quadAtZ(0.0f, -10.0f, 10.0f, -10.0f, 10.0f, glass, true);
    b.quadAtZ(-float(thickness), -10.0f, 10.0f, -10.0f, 10.0f, glass, false);
    GradientBackdrop::add(b, -depth);
    b.darkness();
    *out = render(b.s, orthographic({0, 0, 1}, {std::sin(theta), 0, -std::cos(theta)}), 1, 1);
    return GradientBackdrop::position(out->color[0]);
  };
  ref::ReferenceImage image;
  double near = hitX(2.0f, &image);
  EXPECT_EQ(image.interfaces[0], 2u);
  EXPECT_EQ(image.outcome[0], gpu::kOutcomeOpaque);
  EXPECT_EQ(image.instance[0], 0);  // the slab's front face
  EXPECT_NEAR(image.distance[0], 1.0 / std::cos(theta), 1e-14);

  double inside = std::asin(std::sin(theta) / ior);
  double expected = std::tan(theta) * (1.0 + 2.0 - thickness) + std::tan(inside) * thickness;
  EXPECT_NEAR(near, expected, 1e-9);
  // Parallel to the incoming ray: a backdrop 2 further away moves the hit by 2 tan(theta).
  double far = hitX(4.0f, &image);
  EXPECT_NEAR(far - near, 2.0 * std::tan(theta), 1e-9);
}

TEST(ReferenceTracer, RayInsideDenseMediumBeyondCriticalAngleIsReflected) {
  const double theta = 1.0;  // critical angle for 1.5: asin(1 / 1.5) = 0.73
  SceneBuilder b;
  b.quadAtZ(0.0f, -10.0f, 10.0f, -10.0f, 10.0f, b.material(refractive(1.5f)));  // the medium lies below z = 0
  GradientBackdrop::add(b, -1.5f);
  b.darkness();
  ref::ReferenceImage image = render(b.s, orthographic({0, 0, -0.5}, {std::sin(theta), 0, std::cos(theta)}), 1, 1);
  EXPECT_EQ(image.interfaces[0], 1u);  // the reflection counts as one interface
  EXPECT_EQ(image.outcome[0], gpu::kOutcomeOpaque);
  // Mirrored at z = 0: 0.5 up to the surface, 1.5 down to the backdrop.
  EXPECT_NEAR(GradientBackdrop::position(image.color[0]), 2.0 * std::tan(theta), 1e-9);
}

TEST(ReferenceTracer, RayInsideDenseMediumBelowCriticalAngleLeavesIt) {
  SceneBuilder b;
  b.quadAtZ(0.0f, -10.0f, 10.0f, -10.0f, 10.0f, b.material(refractive(1.5f)));
  GradientBackdrop::add(b, -3.0f);
  b.darkness();
  ref::ReferenceImage image = render(b.s, orthographic({0, 0, -1}, {std::sin(0.5), 0, std::cos(0.5)}), 1, 1);
  EXPECT_EQ(image.interfaces[0], 1u);
  EXPECT_EQ(image.outcome[0], gpu::kOutcomeMiss);
}

TEST(ReferenceTracer, UnitIorQuadIsInvisible) {
  // A lit, textured backdrop seen in perspective, with and without a tilted
  // IOR 1 quad in front of part of it.
  SceneBuilder b;
  scene::Texture t;
  t.width = t.height = 3;
  for (int i = 0; i < 9; ++i) t.rgba.insert(t.rgba.end(), {uint8_t(20 * i), uint8_t(255 - 25 * i), uint8_t(90 + 15 * i), 255});
  scene::Material backdrop = opaque({0.9f, 0.8f, 0.7f});
  backdrop.baseColorTexture.texture = b.texture(t);
  b.quadAtZ(-3.0f, -2.0f, 2.0f, -2.0f, 2.0f, b.material(backdrop));
  scene::Light sun;
  sun.type = scene::LightType::Directional;
  b.light(sun, glm::vec3(0.0f), glm::vec3(0.3f, -0.4f, -1.0f));
  scene::Light bulb;
  b.light(bulb, glm::vec3(0.5f, 0.5f, -1.0f), glm::vec3(0, 0, -1));
  ref::ReferenceImage without = render(b.s, scene::View{}, 24, 18);

  b.quad({glm::vec3(-0.6f, -0.5f, -1.2f), glm::vec3(0.5f, -0.4f, -1.6f), glm::vec3(0.5f, 0.6f, -1.5f),
          glm::vec3(-0.6f, 0.4f, -1.0f)},
         b.material(refractive(1.0f)));
  ref::ReferenceImage with = render(b.s, scene::View{}, 24, 18);

  size_t covered = 0;
  for (size_t i = 0; i < with.color.size(); ++i) {
    if (with.interfaces[i] == 1) ++covered;
    ASSERT_NEAR(with.color[i].r, without.color[i].r, 1e-12) << "pixel " << i;
    ASSERT_NEAR(with.color[i].g, without.color[i].g, 1e-12) << "pixel " << i;
    ASSERT_NEAR(with.color[i].b, without.color[i].b, 1e-12) << "pixel " << i;
  }
  EXPECT_GT(covered, 20u);
}

TEST(ReferenceTracer, RefractiveFaceTintsWhatIsSeenThroughIt) {
  SceneBuilder b;
  b.quadAtZ(-3.0f, -2.0f, 2.5f, -2.0f, 2.0f, b.material(opaque({0.9f, 0.8f, 0.7f})));
  b.quadAtZ(-1.0f, -2.0f, 2.5f, -2.0f, 2.0f, b.material(refractive(1.0f, {0.5f, 0.25f, 1.0f})));
  ref::ReferenceImage image = render(b.s, scene::View{}, 3, 3);
  glm::dvec3 base(0.9f, 0.8f, 0.7f);
  glm::dvec3 behind = kAmbient * base + kHeadlight * (base / kPi + kSpecular);
  expectColorNear(centre(image), glm::dvec3(0.5, 0.25, 1.0) * behind);
}

TEST(ReferenceTracer, InterfaceLimitEndsTheRayAsAMissWithTheBackgroundColour) {
  SceneBuilder b;
  int clear = b.material(refractive(1.0f));
  for (int k = 1; k <= 5; ++k) b.quadAtZ(-float(k), -2.0f, 2.5f, -2.0f, 2.0f, clear);
  b.quadAtZ(-10.0f, -20.0f, 25.0f, -20.0f, 20.0f, b.material(opaque({1.0f, 1.0f, 1.0f})));

  ref::ReferenceImage limited = render(b.s, scene::View{}, 3, 3, 3);
  size_t c = limited.index(1, 1);
  EXPECT_EQ(limited.outcome[c], gpu::kOutcomeInterfaceLimit);
  EXPECT_EQ(limited.interfaces[c], 3u);
  expectColorNear(limited.color[c], ref::ReferenceSettings{}.background, 0.0);

  ref::ReferenceImage enough = render(b.s, scene::View{}, 3, 3, 5);
  EXPECT_EQ(enough.outcome[c], gpu::kOutcomeOpaque);
  EXPECT_EQ(enough.interfaces[c], 5u);
}

/// The colour of an emissive-only quad whose texture transform sends every
/// texture coordinate to `uv`: exactly what the sampler returns there.
glm::dvec3 sampleThroughRender(const scene::Texture& texture, glm::vec2 uv) {
  SceneBuilder b;
  scene::Material m = emissiveOnly(b.texture(texture));
  m.emissiveTexture.transform = glm::mat3(glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(uv, 1.0f));
  b.quadAtZ(-1.0f, -1.0f, 1.5f, -1.0f, 1.0f, b.material(m));
  b.darkness();
  return render(b.s, orthographic({0, 0, 0}, {0, 0, -1}), 1, 1).color[0];
}

TEST(ReferenceTracer, NearestSamplingWrapsByRepeatMirrorAndClamp) {
  // Texels (x, y): (0, 0) = 10, (1, 0) = 60, (0, 1) = 110, (1, 1) = 160.
  scene::Texture t = greyTexture(2, 2, {10, 60, 110, 160});
  t.linearFilter = false;
  auto texel = [](int x, int y) { return srgbToLinear(10 + 50 * x + 100 * y); };
  struct Case {
    float u;
    int repeat, mirror, clamp;  // the texel column each mode picks
  };
  // floor(u * 2): 2, -1, 3, 5.
  const Case cases[] = {{1.25f, 0, 1, 1}, {-0.25f, 1, 0, 0}, {1.75f, 1, 0, 1}, {2.75f, 1, 1, 1}};
  for (const Case& c : cases) {
    t.repeatS = t.repeatT = true, t.mirrorS = t.mirrorT = false;
    EXPECT_DOUBLE_EQ(sampleThroughRender(t, {c.u, 0.25f}).r, texel(c.repeat, 0)) << "repeat S at u = " << c.u;
    EXPECT_DOUBLE_EQ(sampleThroughRender(t, {0.25f, c.u}).r, texel(0, c.repeat)) << "repeat T at v = " << c.u;
    t.mirrorS = t.mirrorT = true;
    EXPECT_DOUBLE_EQ(sampleThroughRender(t, {c.u, 0.25f}).r, texel(c.mirror, 0)) << "mirror S at u = " << c.u;
    EXPECT_DOUBLE_EQ(sampleThroughRender(t, {0.25f, c.u}).r, texel(0, c.mirror)) << "mirror T at v = " << c.u;
    t.repeatS = t.repeatT = false, t.mirrorS = t.mirrorT = false;
    EXPECT_DOUBLE_EQ(sampleThroughRender(t, {c.u, 0.25f}).r, texel(c.clamp, 0)) << "clamp S at u = " << c.u;
    EXPECT_DOUBLE_EQ(sampleThroughRender(t, {0.25f, c.u}).r, texel(0, c.clamp)) << "clamp T at v = " << c.u;
  }
}

TEST(ReferenceTracer, TexelsAreDecodedFromSrgbBeforeBilinearFiltering) {
  // Row 0 (v < 0.5): 128 then 255; row 1: black.
  scene::Texture t = greyTexture(2, 2, {128, 255, 0, 0});
  t.repeatS = t.repeatT = false;
  const double grey = srgbToLinear(128);  // 0.2158605, not 128 / 255
  EXPECT_NEAR(grey, 0.2158605, 1e-7);
  EXPECT_DOUBLE_EQ(sampleThroughRender(t, {0.25f, 0.25f}).r, grey);  // a texel's centre
  EXPECT_DOUBLE_EQ(sampleThroughRender(t, {0.5f, 0.25f}).r, (grey + 1.0) / 2.0);
  EXPECT_DOUBLE_EQ(sampleThroughRender(t, {0.5f, 0.5f}).r, (grey + 1.0) / 4.0);
  EXPECT_NEAR(sampleThroughRender(t, {0.375f, 0.25f}).r, 0.75 * grey + 0.25, 1e-15);
}

TEST(ReferenceTracer, TexCoordAndTransformPickTheUvs) {
  // Texels: (0, 0) = 10, (1, 0) = 60, (0, 1) = 110, (1, 1) = 160, nearest.
  scene::Texture t = greyTexture(2, 2, {10, 60, 110, 160});
  t.linearFilter = false;
  auto render1 = [&](int texCoord, glm::mat3 transform, bool withSet1) {
    SceneBuilder b;
    scene::Material m = emissiveOnly(b.texture(t));
    m.emissiveTexture.texCoord = texCoord;
    m.emissiveTexture.transform = transform;
    b.quadAtZ(-1.0f, -1.0f, 1.5f, -1.0f, 1.0f, b.material(m));
    scene::Shape& shape = b.s.shapes.back();
    shape.texcoords0.assign(4, glm::vec2(0.25f, 0.75f));
    if (withSet1) shape.texcoords1.assign(4, glm::vec2(0.75f, 0.25f));
    b.darkness();
    return render(b.s, orthographic({0, 0, 0}, {0, 0, -1}), 1, 1).color[0].r;
  };
  const glm::mat3 identity(1.0f);
  glm::mat3 shift(1.0f);
  shift[2] = glm::vec3(0.5f, -0.5f, 1.0f);  // uv + (0.5, -0.5)
  EXPECT_DOUBLE_EQ(render1(0, identity, true), srgbToLinear(110));
  EXPECT_DOUBLE_EQ(render1(1, identity, true), srgbToLinear(60));
  EXPECT_DOUBLE_EQ(render1(0, shift, true), srgbToLinear(60));
  EXPECT_DOUBLE_EQ(render1(1, identity, false), srgbToLinear(10));  // no TEXCOORD_1: (0, 0)
}

TEST(ReferenceTracer, NodeTransformPlacesTheShapeAndNamesItsItemAndTriangle) {
  SceneBuilder b;
  int white = b.material(opaque({1, 1, 1}));
  b.quadAtZ(0.0f, -1.0f, 1.5f, -1.0f, 1.0f, white);
  int moved = b.quadAtZ(0.0f, -1.0f, 1.5f, -1.0f, 1.0f, white);
  b.s.nodes[size_t(moved)].translation = {0.0f, 0.0f, -1.0f};
  b.s.nodes[size_t(0)].translation = {0.0f, 0.0f, -3.0f};
  ref::ReferenceImage image = render(b.s, scene::View{}, 3, 3);
  size_t c = image.index(1, 1);
  EXPECT_EQ(image.instance[c], 1);
  // (0, 0) lies in triangle (0 2 3), above the diagonal from (-1, -1) to (1.5, 1).
  EXPECT_EQ(image.primitive[c], 1);
  EXPECT_NEAR(image.distance[c], 1.0, 1e-15);
  // Beside both quads: a miss.
  ref::ReferenceImage wide = render(b.s, orthographic({5, 5, 0}, {0, 0, -1}), 1, 1);
  EXPECT_EQ(wide.instance[0], -1);
  EXPECT_EQ(wide.primitive[0], -1);
  EXPECT_EQ(wide.outcome[0], gpu::kOutcomeMiss);
  EXPECT_TRUE(std::isinf(wide.distance[0]));
  expectColorNear(wide.color[0], ref::ReferenceSettings{}.background, 0.0);
}

TEST(ReferenceTracer, DegenerateAndNonFiniteTrianglesAreNeverHit) {
  SceneBuilder b;
  int white = b.material(opaque({1, 1, 1}));
  b.quadAtZ(-3.0f, -2.0f, 2.5f, -2.0f, 2.0f, white);
  scene::Shape broken;
  broken.material = white;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // A sliver with no area through the view's axis, and a triangle with a NaN corner.
  broken.positions = {{-1, -1, -1}, {0, 0, -1}, {1, 1, -1}, {-1, -1, -2}, {2, -1, -2}, {0, nan, -2}};
  broken.normals.assign(6, glm::vec3(0, 0, 1));
  broken.indices = {0, 1, 2, 3, 4, 5};
  b.addShape(broken);
  ref::ReferenceImage image = render(b.s, scene::View{}, 9, 9);
  for (size_t i = 0; i < image.instance.size(); ++i) EXPECT_NE(image.instance[i], 1) << "pixel " << i;
  EXPECT_EQ(image.instance[image.index(4, 4)], 0);
}

TEST(ReferenceTracer, MorphedItemIsTracedWhereItsTargetsMoveIt) {
  SceneBuilder b;
  b.quadAtZ(-2.0f, -1.0f, 1.5f, -1.0f, 1.0f, b.material(opaque({1, 1, 1})));
  scene::MorphTarget closer;
  closer.positions.assign(4, glm::vec3(0.0f, 0.0f, 0.5f));
  b.s.shapes[0].targets = {closer};
  b.s.meshes[0].weights = {0.0f};
  b.s.nodes[0].weights = {1.5f};
  ref::ReferenceImage image = render(b.s, scene::View{}, 3, 3);
  EXPECT_NEAR(image.distance[image.index(1, 1)], 2.0 - 0.75, 1e-12);
}

// The reference's settings for a width x height picture of `scene` at `pose`, framed as snell frames it.
ref::ReferenceSettings framed(const scene::Scene& scene, const scene::Pose& pose, uint32_t width, uint32_t height) {
  ref::ReferenceSettings settings;
  settings.width = width;
  settings.height = height;
  settings.view = scene::resolveView(scene, pose, {});
  return settings;
}

TEST(ReferenceTracer, ThreadCountDoesNotChangeTheImage) {
  scene::Scene eye = scene::makeEye({.resolution = 16});
  scene::Pose pose = scene::evaluate(eye, 0.0);
  ref::ReferenceSettings settings = framed(eye, pose, 32, 24);
  settings.threads = 1;
  ref::ReferenceImage one = ref::renderReference(eye, pose, settings);
  settings.threads = 3;
  ref::ReferenceImage three = ref::renderReference(eye, pose, settings);
  EXPECT_EQ(one.color, three.color);
  EXPECT_EQ(one.instance, three.instance);
  EXPECT_EQ(one.interfaces, three.interfaces);
}

TEST(ReferenceTracer, ProceduralEyeShowsTheIrisThroughTheCorneaWithoutNaN) {
  scene::Scene eye = scene::makeEye({.resolution = 16});
  scene::Pose pose = scene::evaluate(eye, 0.0);
  ref::ReferenceImage image = ref::renderReference(eye, pose, framed(eye, pose, 64, 48));
  // The cornea's tip is one refractive surface over the iris: a ray crosses
  // it once and ends on the iris or pupil behind it.
  size_t throughCornea = 0, opaque = 0;
  for (size_t i = 0; i < image.color.size(); ++i) {
    const glm::dvec3& c = image.color[i];
    ASSERT_TRUE(std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b)) << "pixel " << i;
    ASSERT_FALSE(std::isnan(image.distance[i])) << "pixel " << i;
    if (image.outcome[i] == gpu::kOutcomeOpaque) ++opaque;
    if (image.instance[i] < 0) continue;
    const scene::Shape& first = eye.shapes[size_t(pose.items[size_t(image.instance[i])].shape)];
    if (eye.materials[size_t(first.material)].refractive() && image.interfaces[i] >= 1 &&
        image.outcome[i] == gpu::kOutcomeOpaque) {
      ++throughCornea;
    }
  }
  EXPECT_GT(throughCornea, 50u);
  EXPECT_GT(opaque, image.color.size() / 4);
}

TEST(SahBvh, BinnedCostOfFourBoxesMatchesTheHandBuiltTree) {
  // Unit cubes at x = 0, 1.2, 3 and a far one at 20. The best first cut sets
  // the far cube apart (18 * 3 + 6 * 1 = 60 against 172 and 246); then 0 | 1.2 3
  // loses to 0 1.2 | 3 (27.6 against 32.4).
  auto cube = [](double x) {
    ref::Aabb b;
    b.lo = {x, 0, 0};
    b.hi = {x + 1, 1, 1};
    return b;
  };
  std::vector<ref::Aabb> boxes = {cube(20), cube(0), cube(3), cube(1.2)};
  // Internal: root [0, 21] 86, [0, 4] 18, [0, 2.2] 10.8; leaves 4 * 6.
  EXPECT_NEAR(ref::binnedSahCost(boxes), (86.0 + 18.0 + 10.8 + 24.0) / 86.0, 1e-12);
}

TEST(SahBvh, CoincidentCentroidsSplitInTheMiddleOfTheIndexRange) {
  // Nested cubes of half-size 1, 2, 3, 4 about the origin: no plane separates
  // them, so the cut is by index, {1, 2} | {3, 4}.
  std::vector<ref::Aabb> boxes;
  for (double s : {1.0, 2.0, 3.0, 4.0}) {
    ref::Aabb b;
    b.lo = glm::dvec3(-s);
    b.hi = glm::dvec3(s);
    boxes.push_back(b);
  }
  auto area = [](double s) { return 24.0 * s * s; };
  double expected = (area(4) + area(2) + area(4) + area(1) + area(2) + area(3) + area(4)) / area(4);
  EXPECT_NEAR(ref::binnedSahCost(boxes), expected, 1e-12);
}

TEST(SahBvh, SahCostSumsAreasOverTheRootArea) {
  ref::Aabb root, half, unit;
  root.lo = glm::dvec3(0);
  root.hi = glm::dvec3(2, 1, 1);  // area 10
  half.lo = glm::dvec3(0);
  half.hi = glm::dvec3(1, 1, 0.5);  // area 4
  unit.lo = glm::dvec3(0);
  unit.hi = glm::dvec3(1);  // area 6
  EXPECT_DOUBLE_EQ(ref::surfaceArea(root), 10.0);
  EXPECT_DOUBLE_EQ(ref::surfaceArea(ref::Aabb{}), 0.0);
  EXPECT_DOUBLE_EQ(ref::sahCost({root}, {unit, half}, root), (10.0 + 6.0 + 4.0) / 10.0);
  EXPECT_DOUBLE_EQ(ref::binnedSahCost({unit}), 1.0);  // one leaf, the root itself
  EXPECT_DOUBLE_EQ(ref::binnedSahCost({}), 0.0);
}

}  // namespace
}  // namespace snell::test
