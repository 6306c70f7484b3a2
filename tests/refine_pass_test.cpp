// The GPU refine pass against its CPU double-precision twin (ref::refineOnCpu)
// and OpenSubdiv's rest pose: a host moves a subdivision cage, the next frame
// refines it into the buffers the trees and the trace read.
#include "gpu_test.h"

#include "ref/refine.h"
#include "render/one_view.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/scene_builder.h"
#include "scene/subdivision.h"
#include "scene/view.h"
#include "stress/stress.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

namespace snell::test {
namespace {

// A rounded box cage: a cube with one creased edge loop and face-varying
// texcoords (a seam down one side), so every table of the pass is used.
scene::SubdivisionCage boxCage(uint32_t level) {
  scene::SubdivisionCage cage;
  cage.level = level;
  for (int i = 0; i < 8; ++i) cage.positions.push_back({i & 1 ? 0.6f : -0.6f, i & 2 ? 0.4f : -0.4f, i & 4 ? 0.5f : -0.5f});
  cage.faceVertexIndices = {0, 4, 6, 2, 1, 3, 7, 5, 0, 1, 5, 4, 2, 6, 7, 3, 0, 2, 3, 1, 4, 5, 7, 6};
  cage.faceVertexCounts.assign(6, 4);
  cage.creaseIndices = {4, 5, 7, 6, 4};
  cage.creaseLengths = {5};
  cage.creaseSharpnesses = {3.0f};
  for (size_t c = 0; c < cage.faceVertexIndices.size(); ++c) {
    const glm::vec3& p = cage.positions[cage.faceVertexIndices[c]];
    cage.uvIndices.push_back(uint32_t(cage.uvs.size()));
    cage.uvs.push_back({p.x + float(c / 4), p.y});  // each face an island of its own
  }
  return cage;
}

struct CageScene {
  scene::Scene scene;
  scene::Pose pose;
};

CageScene cageScene(const scene::SubdivisionCage& cage) {
  CageScene out;
  out.scene.source = "a subdivision cage";
  scene::Shape shape;
  shape.name = "box";
  std::vector<std::string> warnings;
  scene::subdivide(cage, shape, "box", warnings);
  EXPECT_TRUE(warnings.empty());
  scene::addRootShape(out.scene, std::move(shape));
  out.pose = scene::evaluate(out.scene, 0.0);
  return out;
}

// A frame of a small traced view: enough for the update (copies, refine, trees) to run.
render::FrameStats drawFrame(render::Renderer& renderer, const scene::Pose& pose, const scene::Scene& scene) {
  scene::ViewRequest request;
  request.lookAt = scene::LookAt{{0.0, 0.0, 4.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  render::FrameSettings settings{32, 32, scene::resolveView(scene, pose, request), glm::vec3(0.0f), 8};
  return render::renderFrame(renderer, pose, settings).stats;
}

// The cage as a rig moves it.
std::vector<glm::dvec3> twisted(const std::vector<glm::vec3>& cage) {
  std::vector<glm::dvec3> out;
  for (const glm::vec3& p : cage) {
    double a = 0.9 * p.y;
    out.push_back({std::cos(a) * p.x + std::sin(a) * p.z, 1.2 * p.y, -std::sin(a) * p.x + std::cos(a) * p.z});
  }
  return out;
}

class RefinePass : public GpuTest {};

TEST_F(RefinePass, AMovedCageIsRefinedAsTheCpuTwinRefinesIt) {
  for (scene::SubdivisionNormals normals : {scene::SubdivisionNormals::Limit, scene::SubdivisionNormals::Mesh}) {
    for (bool limitSurface : {false, true}) {
      SCOPED_TRACE(std::string(normals == scene::SubdivisionNormals::Limit ? "limit" : "mesh") + " normals, " +
                   (limitSurface ? "on the limit surface" : "refined vertices"));
      scene::SubdivisionCage cage = boxCage(3);
      cage.normals = normals;
      cage.limitSurface = limitSurface;
      CageScene s = cageScene(cage);
      render::RendererOptions options;
      options.keepVertices = true;
      render::Renderer renderer(context(), s.scene, s.pose, options);
      drawFrame(renderer, s.pose, s.scene);

      std::vector<glm::dvec3> moved = twisted(cage.positions);
      render::KeptVertices kept = renderer.keptVertices(0);
      ASSERT_EQ(kept.count, 8u);  // the host writes the cage
      for (size_t v = 0; v < moved.size(); ++v) {
        for (int k = 0; k < 3; ++k) kept.positions[3 * v + size_t(k)] = float(moved[v][k]);
      }
      renderer.markDirty(0);
      render::FrameStats stats = drawFrame(renderer, s.pose, s.scene);
      EXPECT_EQ(stats.shapesRefined, 1u);
      EXPECT_EQ(stats.verticesRefined, uint32_t(s.scene.shapes[0].vertexCount()));

      const render::GeometryRange& range = renderer.sceneGpu().geometries[0];
      std::vector<float> positions(size_t(range.vertexCount) * 3), gpuNormals(positions.size());
      vk::download(context(), renderer.sceneGpu().positions, positions.data(), positions.size() * 4,
                   VkDeviceSize(range.firstVertex) * 12);
      vk::download(context(), renderer.sceneGpu().normals, gpuNormals.data(), gpuNormals.size() * 4,
                   VkDeviceSize(range.firstVertex) * 12);
      std::vector<glm::dvec3> expected, expectedNormals;
      ref::refineOnCpu(*s.scene.shapes[0].refinement, moved, expected, expectedNormals);
      ASSERT_EQ(expected.size(), size_t(range.vertexCount));
      double worst = 0.0, worstAngle = 0.0;
      for (size_t v = 0; v < expected.size(); ++v) {
        glm::dvec3 p(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
        glm::dvec3 n(gpuNormals[3 * v], gpuNormals[3 * v + 1], gpuNormals[3 * v + 2]);
        worst = std::max(worst, glm::length(p - expected[v]));
        worstAngle = std::max(worstAngle, 1.0 - glm::dot(n, expectedNormals[v]));
      }
      EXPECT_LT(worst / 1.6, 1e-5);  // of the cage's diagonal
      EXPECT_LT(worstAngle, 1e-5);

      // A frame whose cage did not move refines nothing.
      EXPECT_EQ(drawFrame(renderer, s.pose, s.scene).shapesRefined, 0u);
    }
  }
}

// A cage whose faces carry two materials (USD subsets, Blender's
// material_index) is one refinement and one refine job, whose vertices both
// materials' triangles read; with two materials alike it draws as the
// one-material cage, moved or not.
TEST_F(RefinePass, ACageWithTwoMaterialsIsRefinedOnceForBoth) {
  scene::SubdivisionCage cage = boxCage(2);
  CageScene one = cageScene(cage), two;
  two.scene.source = "a cage of two materials";
  scene::Shape shape;
  std::vector<std::string> warnings;
  std::vector<uint32_t> triangleFaces;
  scene::subdivide(cage, shape, "box", warnings, scene::kMaxRefinedVertices, &triangleFaces);
  ASSERT_EQ(triangleFaces.size(), shape.triangleCount());
  // Opaque: glass faces of two materials would be two media, entered through one and left through the other.
  scene::Material glow;
  glow.emissiveFactor = {0.9f, 0.5f, 0.2f};
  for (scene::Scene* s : {&one.scene, &two.scene}) s->materials = {glow, glow};
  one.scene.shapes[0].material = 0;
  scene::addRootShape(two.scene, std::move(shape));
  std::vector<int> triangleMaterials;
  for (uint32_t face : triangleFaces) triangleMaterials.push_back(face < 3 ? 0 : 1);  // the first three cage faces, then the rest
  ASSERT_EQ(scene::splitByMaterial(two.scene, 0, triangleMaterials), std::vector<int>{1});
  two.pose = scene::evaluate(two.scene, 0.0);
  ASSERT_EQ(two.scene.shapes.size(), 2u);
  EXPECT_EQ(two.scene.shapes[1].vertexSource, 0);
  EXPECT_EQ(two.scene.shapes[1].refinement.get(), two.scene.shapes[0].refinement.get()) << "refined twice";
  EXPECT_EQ(two.scene.shapes[0].triangleCount() + two.scene.shapes[1].triangleCount(),
            one.scene.shapes[0].triangleCount());

  render::RendererOptions options;
  options.keepVertices = true;
  render::Renderer oneRenderer(context(), one.scene, one.pose, options), twoRenderer(context(), two.scene, two.pose, options);
  EXPECT_EQ(twoRenderer.sceneGpu().vertexCount, oneRenderer.sceneGpu().vertexCount) << "the part's vertices uploaded again";
  scene::ViewRequest request;
  request.lookAt = scene::LookAt{{0.3, 0.5, 3.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  auto image = [&](render::Renderer& r, const CageScene& s) {
    render::FrameSettings settings{48, 48, scene::resolveView(s.scene, s.pose, request), glm::vec3(0.2f), 8};
    return render::renderFrame(r, s.pose, settings);
  };
  for (int frame = 0; frame < 2; ++frame) {
    if (frame == 1) {  // the host twists the cage: one copy, one refine job for both materials
      std::vector<glm::dvec3> moved = twisted(cage.positions);
      for (render::Renderer* r : {&oneRenderer, &twoRenderer}) {
        render::KeptVertices kept = r->keptVertices(0);
        for (size_t v = 0; v < moved.size(); ++v) {
          for (int k = 0; k < 3; ++k) kept.positions[3 * v + size_t(k)] = float(moved[v][k]);
        }
        r->markDirty(0);
      }
    }
    render::RenderedFrame oneImage = image(oneRenderer, one), twoImage = image(twoRenderer, two);
    if (frame == 1) {
      EXPECT_EQ(twoImage.stats.shapesCopied, 1u);
      EXPECT_EQ(twoImage.stats.shapesRefined, 1u);
      EXPECT_EQ(twoImage.stats.verticesRefined, oneImage.stats.verticesRefined);
    }
    ASSERT_EQ(twoImage.rgba.size(), oneImage.rgba.size());
    float worst = 0.0f;  // a ray through an edge between the materials may meet the other triangle of it
    for (size_t i = 0; i < oneImage.rgba.size(); ++i) {
      const glm::vec4 d = glm::abs(twoImage.rgba[i] - oneImage.rgba[i]);
      worst = std::max(worst, std::max(std::max(d.r, d.g), d.b));
    }
    EXPECT_LT(worst, 1.0f / 255.0f) << "frame " << frame << ": two materials alike drew otherwise";
  }
}

TEST_F(RefinePass, TheRestCageRefinesToOpenSubdivsRestPose) {
  CageScene s = cageScene(boxCage(2));
  render::RendererOptions options;
  options.keepVertices = true;
  render::Renderer renderer(context(), s.scene, s.pose, options);
  renderer.markDirty(0);  // the kept cage is the rest pose: refined on the GPU, it must land where the CPU put it
  drawFrame(renderer, s.pose, s.scene);
  const scene::Shape& shape = s.scene.shapes[0];
  std::vector<float> positions(shape.vertexCount() * 3);
  vk::download(context(), renderer.sceneGpu().positions, positions.data(), positions.size() * 4, 0);
  for (size_t v = 0; v < shape.vertexCount(); ++v) {
    glm::vec3 p(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
    EXPECT_LT(glm::length(p - shape.positions[v]), 1.6e-5f) << "vertex " << v;
  }
}

}  // namespace
}  // namespace snell::test

namespace snell::test {
namespace {

// A checkerboard card of self-lit squares (geometry, not a texture: no
// filtering, no UV convention between the picture and the parity below).
constexpr float kCardZ = -1.0f, kCardHalf = 3.0f, kCell = 0.75f;

bool lightCellAt(double x, double y) {
  long cx = long(std::floor((x + kCardHalf) / kCell)), cy = long(std::floor((y + kCardHalf) / kCell));
  return (cx + cy) % 2 != 0;
}

void addCard(scene::Scene& s) {
  for (int light = 0; light < 2; ++light) {
    scene::Material m;
    m.name = light ? "light cells" : "dark cells";
    m.baseColorFactor = {0, 0, 0, 1};
    m.emissiveFactor = glm::vec3(light ? 1.0f : 0.05f);
    scene::Shape shape;
    shape.name = m.name;
    shape.material = scene::addMaterial(s, m);
    for (float y = -kCardHalf; y < kCardHalf - 1e-3f; y += kCell) {
      for (float x = -kCardHalf; x < kCardHalf - 1e-3f; x += kCell) {
        if (lightCellAt(x + 0.5 * kCell, y + 0.5 * kCell) != bool(light)) continue;
        scene::addQuad(shape, {x, y, kCardZ}, {x + kCell, y, kCardZ}, {x + kCell, y + kCell, kCardZ}, {x, y + kCell, kCardZ});
      }
    }
    scene::addRootShape(s, shape);
  }
}

// Snell's law for unit d and a unit normal n facing d's side; false at total internal reflection.
bool refract(const glm::dvec3& d, const glm::dvec3& n, double eta, glm::dvec3& out) {
  double c = -glm::dot(d, n), k = 1.0 - eta * eta * (1.0 - c * c);
  if (k < 0.0) return false;
  out = glm::normalize(eta * d + (eta * c - std::sqrt(k)) * n);
  return true;
}

// Where the analytic plano-convex lens (corneaCage's: the cap of a unit
// sphere centred at z = -0.5 over the disc z = 0) sends a ray: whether it
// lands on a light cell; false when it does not pass through cap and base.
bool analyticLensCell(const scene::Ray& ray, double ior, bool& light) {
  const glm::dvec3 centre(0.0, 0.0, -0.5);
  const double rim = std::sqrt(0.75);
  glm::dvec3 o = ray.origin - centre;
  double b = glm::dot(o, ray.direction), c = glm::dot(o, o) - 1.0, disc = b * b - c;
  if (disc <= 0.0) return false;
  glm::dvec3 p = ray.origin + (-b - std::sqrt(disc)) * ray.direction, inside;
  if (p.z < 0.0 || !refract(ray.direction, glm::normalize(p - centre), 1.0 / ior, inside) || inside.z >= 0.0) return false;
  glm::dvec3 q = p + (-p.z / inside.z) * inside, out;
  if (std::hypot(q.x, q.y) >= rim || !refract(inside, {0.0, 0.0, 1.0}, ior, out)) return false;
  glm::dvec3 hit = q + ((kCardZ - q.z) / out.z) * out;
  if (std::abs(hit.x) >= kCardHalf || std::abs(hit.y) >= kCardHalf) return false;
  light = lightCellAt(hit.x, hit.y);
  return true;
}

class CorneaLens : public GpuTest {
 protected:
  // The share of rays through the lens whose traced colour is the analytic
  // lens's cell: over the whole lens, and over its central zone (rays
  // aimed within 0.7 of the axis, four fifths of the rim's radius).
  struct Parity {
    double whole = 0.0, central = 0.0;
  };
  Parity parity(uint32_t level, scene::SubdivisionNormals normals) {
    scene::Scene s;
    s.source = "a cornea over a checkerboard";
    scene::Material glass = scene::clearGlass("cornea", 1.376f);
    scene::SubdivisionCage cage = stress::corneaCage(6, 24, 1.0f, 0.5f, level);
    cage.normals = normals;
    scene::Shape cornea;
    std::vector<std::string> warnings;
    scene::subdivide(cage, cornea, "cornea", warnings);
    cornea.material = scene::addMaterial(s, glass);
    scene::addRootShape(s, cornea);
    addCard(s);
    scene::Pose pose = scene::evaluate(s, 0.0);
    // Rays from an eye off the axis to a grid over the base disc.
    const glm::dvec3 eye(0.15, 0.1, 3.0);
    const uint32_t side = 96;
    std::vector<scene::Ray> rays;
    for (uint32_t j = 0; j < side; ++j) {
      for (uint32_t i = 0; i < side; ++i) {
        glm::dvec3 at(-0.85 + 1.7 * (i + 0.5) / side, -0.85 + 1.7 * (j + 0.5) / side, 0.0);
        rays.push_back({eye, glm::normalize(at - eye)});
      }
    }
    scene::ViewRequest request;
    request.lookAt = scene::LookAt{eye, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
    render::FrameSettings settings{side, side, scene::resolveView(s, pose, request), glm::vec3(0.0f), 8};
    settings.optics.fresnel = false;  // the glass passes all of its light
    settings.rays = rays;
    render::Renderer renderer(context(), s, pose);
    render::RenderedFrame frame = render::renderFrame(renderer, pose, settings);
    size_t through = 0, agree = 0, central = 0, centralAgree = 0;
    for (size_t r = 0; r < rays.size(); ++r) {
      bool light = false;
      if (!analyticLensCell(rays[r], 1.376, light)) continue;
      ++through;
      agree += (frame.rgba[r].g > 0.5f) == light;
      glm::dvec3 at = rays[r].origin + (-rays[r].origin.z / rays[r].direction.z) * rays[r].direction;
      if (std::hypot(at.x, at.y) <= 0.7) ++central, centralAgree += (frame.rgba[r].g > 0.5f) == light;
    }
    EXPECT_GT(through, rays.size() / 2);
    return {double(agree) / double(through), double(centralAgree) / double(central)};
  }
};

TEST_F(CorneaLens, ACorneaRefinedTwiceFromACoarseCageRefractsAsTheAnalyticLens) {
  // The cage: 216 faces (6 rings of 24), fitted so that its Catmull-Clark
  // limit surface lies nearest the lens. That surface is not a sphere: near
  // the creased rim it stands off it by up to 0.15% of the radius, which is
  // what keeps the refined lens from a parity of 1 (a fine mesh of the
  // analytic lens itself reaches 1.0000 by this measure).
  Parity cage = parity(0, scene::SubdivisionNormals::Mesh);
  Parity limit = parity(2, scene::SubdivisionNormals::Limit), mesh = parity(2, scene::SubdivisionNormals::Mesh);
  std::printf("analytic lens parity, whole (central): the cage %.4f (%.4f); refined twice, limit normals %.4f (%.4f), "
              "mesh normals %.4f (%.4f)\n", cage.whole, cage.central, limit.whole, limit.central, mesh.whole, mesh.central);
  for (const Parity& refined : {limit, mesh}) {
    EXPECT_GE(refined.whole, 0.98);
    EXPECT_GE(refined.central, 0.99);
    EXPECT_LT(cage.whole, refined.whole - 0.03);  // the cage's facets are prisms
    EXPECT_LT(cage.central, refined.central);
  }
}

}  // namespace
}  // namespace snell::test
