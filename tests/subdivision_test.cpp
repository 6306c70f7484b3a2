// Subdivision surfaces on the CPU: the cage's topology and tags as OpenSubdiv
// refines them, the stencil tables the refine pass walks (through its CPU
// twin, ref::refineOnCpu) against OpenSubdiv's own refinement of the same
// cage, and bad cages.
#include "ref/refine.h"
#include "scene/scene_builder.h"
#include "scene/scene_summary.h"
#include "scene/subdivision.h"

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <gtest/gtest.h>

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <memory>

namespace snell::test {
namespace {

namespace osd = OpenSubdiv::Far;

scene::SubdivisionCage unitCube() {
  scene::SubdivisionCage cage;
  for (int i = 0; i < 8; ++i) cage.positions.push_back({i & 1 ? 0.5f : -0.5f, i & 2 ? 0.5f : -0.5f, i & 4 ? 0.5f : -0.5f});
  // Corner bits: x = 1, y = 2, z = 4; each face counter-clockwise seen from outside.
  cage.faceVertexIndices = {0, 4, 6, 2, 1, 3, 7, 5, 0, 1, 5, 4, 2, 6, 7, 3, 0, 2, 3, 1, 4, 5, 7, 6};
  cage.faceVertexCounts.assign(6, 4);
  return cage;
}

// An open grid of n x n quads in z = 0 with a bump, its boundary free.
scene::SubdivisionCage openGrid(int n) {
  scene::SubdivisionCage cage;
  for (int y = 0; y <= n; ++y) {
    for (int x = 0; x <= n; ++x) {
      float u = float(x) / float(n) - 0.5f, v = float(y) / float(n) - 0.5f;
      cage.positions.push_back({u, v, 0.3f * std::cos(3.0f * u) * std::cos(2.0f * v)});
      cage.uvs.push_back({u + 0.5f, v + 0.5f});
    }
  }
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      uint32_t a = uint32_t(y * (n + 1) + x);
      cage.faceVertexIndices.insert(cage.faceVertexIndices.end(), {a, a + 1, a + uint32_t(n) + 2, a + uint32_t(n) + 1});
      cage.faceVertexCounts.push_back(4);
    }
  }
  return cage;
}

// A pentagon fanned with triangles and a quad: n-gons and triangles in one cage.
scene::SubdivisionCage mixedFaces() {
  scene::SubdivisionCage cage;
  for (int k = 0; k < 5; ++k) {
    float a = 2.0f * glm::pi<float>() * float(k) / 5.0f;
    cage.positions.push_back({std::cos(a), std::sin(a), 0.0f});
  }
  cage.positions.push_back({0.0f, 0.0f, 0.8f});   // 5: the apex over the pentagon
  cage.positions.push_back({2.0f, 0.3f, 0.2f});   // 6, 7: a quad on edge 0-1
  cage.positions.push_back({1.4f, 1.6f, 0.1f});
  cage.faceVertexIndices = {4, 3, 2, 1, 0};  // the pentagon, seen from below
  cage.faceVertexCounts = {5};
  for (uint32_t k = 0; k < 5; ++k) {
    cage.faceVertexIndices.insert(cage.faceVertexIndices.end(), {k, (k + 1) % 5, 5});
    cage.faceVertexCounts.push_back(3);
  }
  cage.faceVertexIndices.insert(cage.faceVertexIndices.end(), {0, 6, 7, 1});
  cage.faceVertexCounts.push_back(4);
  return cage;
}

double diagonal(const std::vector<glm::vec3>& points) {
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::vec3& p : points) lo = glm::min(lo, glm::dvec3(p)), hi = glm::max(hi, glm::dvec3(p));
  return glm::length(hi - lo);
}

// OpenSubdiv's own uniform refinement of `cage` at `positions`, in double:
// the last level's vertices, independent of snell's tables.
struct Vertex {
  glm::dvec3 p{0.0};
  void Clear(void* = nullptr) { p = glm::dvec3(0.0); }
  void AddWithWeight(const Vertex& s, float w) { p += double(w) * s.p; }
};
std::vector<glm::dvec3> openSubdivRefined(const scene::SubdivisionCage& cage, const std::vector<glm::dvec3>& positions) {
  std::vector<int> counts(cage.faceVertexCounts.begin(), cage.faceVertexCounts.end());
  std::vector<int> indices(cage.faceVertexIndices.begin(), cage.faceVertexIndices.end());
  std::vector<int> creases;
  std::vector<float> creaseWeights;
  for (size_t c = 0, at = 0; c < cage.creaseLengths.size(); at += cage.creaseLengths[c++]) {
    for (uint32_t k = 0; k + 1 < cage.creaseLengths[c]; ++k) {
      creases.insert(creases.end(), {int(cage.creaseIndices[at + k]), int(cage.creaseIndices[at + k + 1])});
      creaseWeights.push_back(cage.creaseSharpnesses[c]);
    }
  }
  osd::TopologyDescriptor desc;
  desc.numVertices = int(positions.size());
  desc.numFaces = int(counts.size());
  desc.numVertsPerFace = counts.data();
  desc.vertIndicesPerFace = indices.data();
  desc.numCreases = int(creaseWeights.size());
  desc.creaseVertexIndexPairs = creases.data();
  desc.creaseWeights = creaseWeights.data();
  OpenSubdiv::Sdc::Options options;
  options.SetVtxBoundaryInterpolation(OpenSubdiv::Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
  using Factory = osd::TopologyRefinerFactory<osd::TopologyDescriptor>;
  OpenSubdiv::Sdc::SchemeType type = cage.scheme == scene::SubdivisionScheme::Loop ? OpenSubdiv::Sdc::SCHEME_LOOP
                                     : cage.scheme == scene::SubdivisionScheme::Bilinear
                                         ? OpenSubdiv::Sdc::SCHEME_BILINEAR
                                         : OpenSubdiv::Sdc::SCHEME_CATMARK;
  std::unique_ptr<osd::TopologyRefiner> refiner(Factory::Create(desc, Factory::Options(type, options)));
  refiner->RefineUniform(osd::TopologyRefiner::UniformOptions(int(cage.level)));
  std::vector<Vertex> level(positions.size());
  for (size_t v = 0; v < positions.size(); ++v) level[v].p = positions[v];
  osd::PrimvarRefiner primvars(*refiner);
  for (int l = 1; l <= refiner->GetMaxLevel(); ++l) {
    std::vector<Vertex> next(size_t(refiner->GetLevel(l).GetNumVertices()));
    Vertex* from = level.data();
    Vertex* to = next.data();
    primvars.Interpolate(l, from, to);
    level = std::move(next);
  }
  std::vector<glm::dvec3> out;
  for (const Vertex& v : level) out.push_back(v.p);
  return out;
}

// The worst distance, over the shape's vertices, between the refine pass's
// twin at `positions` and OpenSubdiv's refinement, over the cage's diagonal.
double worstTwinError(const scene::SubdivisionCage& cage, const std::vector<glm::dvec3>& positions) {
  scene::Shape shape;
  std::vector<std::string> warnings;
  scene::subdivide(cage, shape, "cage", warnings);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  std::vector<glm::dvec3> twin, normals;
  ref::refineOnCpu(*shape.refinement, positions, twin, normals);
  std::vector<glm::dvec3> expected = openSubdivRefined(cage, positions);
  double worst = 0.0;
  for (size_t v = 0; v < twin.size(); ++v) {
    worst = std::max(worst, glm::length(twin[v] - expected[shape.refinement->vertexOf[v]]));
  }
  return worst / diagonal(cage.positions);
}

// The cage moved as a host's rig would move it: a twist and a squash.
std::vector<glm::dvec3> deformed(const scene::SubdivisionCage& cage) {
  std::vector<glm::dvec3> out;
  for (const glm::vec3& p : cage.positions) {
    double a = 0.7 * p.z;
    out.push_back({std::cos(a) * p.x - std::sin(a) * p.y, std::sin(a) * p.x + std::cos(a) * p.y, 0.8 * p.z + 0.1 * p.x});
  }
  return out;
}

std::vector<glm::dvec3> atRest(const scene::SubdivisionCage& cage) {
  return std::vector<glm::dvec3>(cage.positions.begin(), cage.positions.end());
}

TEST(Subdivision, ACatmullClarkCubeAtLevelTwoHas98VerticesAnd96Quads) {
  scene::Shape shape;
  std::vector<std::string> warnings;
  scene::subdivide(unitCube(), shape, "cube", warnings);
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(shape.vertexCount(), 98u);
  EXPECT_EQ(shape.triangleCount(), 192u);  // two a quad
  EXPECT_EQ(shape.cageVertices, 8u);
  EXPECT_EQ(shape.writtenVertexCount(), 8u);
}

// Each refined triangle knows its cage face, so a material per face splits
// the surface into parts of one vertex set; the summary counts them all once.
TEST(Subdivision, ACubeSplitByFaceMaterialsKeepsItsVerticesOnceAndEveryTriangle) {
  scene::Scene s;
  scene::Shape shape;
  std::vector<std::string> warnings;
  std::vector<uint32_t> faces;
  scene::subdivide(unitCube(), shape, "cube", warnings, scene::kMaxRefinedVertices, &faces);
  ASSERT_EQ(faces.size(), 192u);
  EXPECT_EQ(std::count(faces.begin(), faces.end(), 5u), 32) << "16 quads of each cage face at level 2";
  scene::addRootShape(s, std::move(shape));
  std::vector<int> materials;
  for (uint32_t f : faces) materials.push_back(f == 0 ? 1 : 0);
  s.materials.resize(2);
  ASSERT_EQ(scene::splitByMaterial(s, 0, materials), std::vector<int>{1});
  // The shape keeps the first material met (cage face 0's), the part takes the other five faces.
  EXPECT_EQ(s.shapes[0].material, 1);
  EXPECT_EQ(s.shapes[0].triangleCount(), 32u);
  EXPECT_EQ(s.shapes[1].material, 0);
  EXPECT_EQ(s.shapes[1].triangleCount(), 160u);
  EXPECT_EQ(s.meshes[0].shapes, (std::vector<int>{0, 1})) << "the part is drawn wherever its source is";
  const scene::SceneSummary summary = scene::summarize(s);
  EXPECT_EQ(summary.vertices, 98u) << "the part's vertices are its source's";
  EXPECT_EQ(summary.triangles, 192u);
  EXPECT_NE(scene::describe(s).find("98 vertices and 192 triangles"), std::string::npos) << scene::describe(s);
}

TEST(Subdivision, TheRefinedCubeIsRoundedInsideItsCageWithNormalsPointingOut) {
  scene::Shape shape;
  std::vector<std::string> warnings;
  scene::subdivide(unitCube(), shape, "cube", warnings);
  for (size_t v = 0; v < shape.positions.size(); ++v) {
    const glm::vec3& p = shape.positions[v];
    EXPECT_LT(std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}), 0.5f);
    EXPECT_GT(glm::dot(shape.normals[v], p), 0.0f) << "vertex " << v;
    EXPECT_NEAR(glm::length(shape.normals[v]), 1.0f, 1e-5f);
  }
}

TEST(Subdivision, InfinitelySharpCreasesKeepTheCubesEdgesAndFaces) {
  scene::SubdivisionCage cage = unitCube();
  // Every edge of the cube a crease of its own.
  const uint32_t edges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3}, {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  for (const auto& e : edges) {
    cage.creaseIndices.insert(cage.creaseIndices.end(), {e[0], e[1]});
    cage.creaseLengths.push_back(2);
    cage.creaseSharpnesses.push_back(10.0f);
  }
  scene::Shape shape;
  std::vector<std::string> warnings;
  scene::subdivide(cage, shape, "creased cube", warnings);
  EXPECT_TRUE(warnings.empty());
  for (const glm::vec3& p : shape.positions) {
    // On the cube's surface: some coordinate at +-0.5.
    EXPECT_NEAR(std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}), 0.5f, 1e-6f);
  }
}

TEST(Subdivision, ASharpCornerStaysWhereTheCageHasIt) {
  scene::SubdivisionCage cage = unitCube();
  cage.cornerIndices = {7};
  cage.cornerSharpnesses = {10.0f};
  scene::Shape shape;
  std::vector<std::string> warnings;
  scene::subdivide(cage, shape, "cube", warnings);
  bool found = false;
  for (const glm::vec3& p : shape.positions) found = found || glm::length(p - glm::vec3(0.5f)) < 1e-6f;
  EXPECT_TRUE(found) << "no refined vertex at the sharp corner";
}

TEST(Subdivision, TheTwinsStencilsRefineAsOpenSubdivDoesOnEveryKindOfCage) {
  scene::SubdivisionCage creased = unitCube();
  creased.creaseIndices = {0, 1, 3, 2};
  creased.creaseLengths = {4};
  creased.creaseSharpnesses = {2.5f};
  scene::SubdivisionCage loop;
  loop.scheme = scene::SubdivisionScheme::Loop;
  for (int i = 0; i < 6; ++i) loop.positions.push_back({i % 2 ? 1.0f : -1.0f, float(i / 2) * 0.7f, 0.2f * float(i % 3)});
  loop.faceVertexIndices = {0, 1, 2, 1, 3, 2, 2, 3, 4, 3, 5, 4};
  loop.faceVertexCounts.assign(4, 3);
  scene::SubdivisionCage bilinear = mixedFaces();
  bilinear.scheme = scene::SubdivisionScheme::Bilinear;
  struct Case {
    const char* name;
    scene::SubdivisionCage cage;
  };
  for (Case c : {Case{"cube", unitCube()}, Case{"creased cube", creased}, Case{"open grid", openGrid(5)},
                 Case{"triangles and a pentagon", mixedFaces()}, Case{"loop triangles", loop},
                 Case{"bilinear", bilinear}}) {
    for (uint32_t level : {1u, 2u, 3u}) {
      c.cage.level = level;
      SCOPED_TRACE(std::string(c.name) + " at level " + std::to_string(level));
      EXPECT_LT(worstTwinError(c.cage, atRest(c.cage)), 1e-5);
      EXPECT_LT(worstTwinError(c.cage, deformed(c.cage)), 1e-5);
    }
  }
}

TEST(Subdivision, TheRestPoseIsTheTwinsRefinementOfTheRestCage) {
  scene::SubdivisionCage cage = openGrid(4);
  cage.level = 3;
  for (int variant = 0; variant < 4; ++variant) {
    cage.limitSurface = variant & 1;
    cage.normals = variant & 2 ? scene::SubdivisionNormals::Limit : scene::SubdivisionNormals::Mesh;
    scene::Shape shape;
    std::vector<std::string> warnings;
    scene::subdivide(cage, shape, "grid", warnings);
    std::vector<glm::dvec3> positions, normals;
    ref::refineOnCpu(*shape.refinement, atRest(cage), positions, normals);
    for (size_t v = 0; v < positions.size(); ++v) {
      EXPECT_LT(glm::length(positions[v] - glm::dvec3(shape.positions[v])), 1e-6) << "vertex " << v;
      EXPECT_GT(glm::dot(normals[v], glm::dvec3(shape.normals[v])), 1.0 - 1e-6) << "vertex " << v;
    }
  }
}

TEST(Subdivision, LimitNormalsAndMeshNormalsAgreeOnASmoothSurface) {
  scene::SubdivisionCage cage = openGrid(6);
  cage.level = 3;
  cage.normals = scene::SubdivisionNormals::Limit;
  scene::Shape limit, mesh;
  std::vector<std::string> warnings;
  scene::subdivide(cage, limit, "grid", warnings);
  cage.normals = scene::SubdivisionNormals::Mesh;
  scene::subdivide(cage, mesh, "grid", warnings);
  double worst = 0.0;
  for (size_t v = 0; v < limit.normals.size(); ++v) {
    worst = std::max(worst, 1.0 - double(glm::dot(limit.normals[v], mesh.normals[v])));
  }
  EXPECT_LT(worst, 0.01);  // within 8 degrees, boundary vertices included
}

TEST(Subdivision, FaceVaryingTexcoordsSplitTheVerticesOfASeam) {
  scene::SubdivisionCage cage = openGrid(2);
  // The same positions, with the grid's left and right columns of faces on two separate islands of UVs.
  cage.uvIndices.clear();
  std::vector<glm::vec2> uvs;
  for (size_t f = 0; f < cage.faceVertexCounts.size(); ++f) {
    for (int k = 0; k < 4; ++k) {
      uint32_t v = cage.faceVertexIndices[4 * f + size_t(k)];
      glm::vec2 uv = cage.uvs[v] + (f % 2 ? glm::vec2(2.0f, 0.0f) : glm::vec2(0.0f));
      cage.uvIndices.push_back(uint32_t(uvs.size()));
      uvs.push_back(uv);
    }
  }
  cage.uvs = uvs;
  scene::Shape shape;
  std::vector<std::string> warnings;
  scene::subdivide(cage, shape, "grid", warnings);
  EXPECT_TRUE(warnings.empty());
  EXPECT_GT(shape.vertexCount(), size_t(shape.refinement->refinedVertices));
  ASSERT_EQ(shape.texcoords0.size(), shape.vertexCount());
  // Each triangle's texcoords stay on one island.
  for (size_t t = 0; t < shape.indices.size(); t += 3) {
    float u0 = shape.texcoords0[shape.indices[t]].x;
    for (int k = 1; k < 3; ++k) EXPECT_EQ(u0 > 1.5f, shape.texcoords0[shape.indices[t + size_t(k)]].x > 1.5f);
  }
}

TEST(Subdivision, HolesAreLeftOutOfTheSurface) {
  scene::SubdivisionCage cage = openGrid(3);
  scene::Shape whole, holed;
  std::vector<std::string> warnings;
  scene::subdivide(cage, whole, "grid", warnings);
  cage.holeIndices = {4};
  scene::subdivide(cage, holed, "grid", warnings);
  EXPECT_EQ(whole.triangleCount() - holed.triangleCount(), 2u * 16u);  // a quad's 16 quads at level 2
}

TEST(Subdivision, LeftHandedFacesAreTurnedRoundSoNormalsStillPointOut) {
  scene::SubdivisionCage cage = unitCube();
  for (size_t f = 0; f < 6; ++f) std::reverse(cage.faceVertexIndices.begin() + long(4 * f), cage.faceVertexIndices.begin() + long(4 * f + 4));
  cage.leftHanded = true;
  scene::Shape shape;
  std::vector<std::string> warnings;
  scene::subdivide(cage, shape, "cube", warnings);
  for (size_t t = 0; t < shape.indices.size(); t += 3) {
    const glm::vec3 &a = shape.positions[shape.indices[t]], &b = shape.positions[shape.indices[t + 1]],
                    &c = shape.positions[shape.indices[t + 2]];
    EXPECT_GT(glm::dot(glm::cross(b - a, c - a), a + b + c), 0.0f) << "triangle " << t / 3 << " faces in";
  }
  for (size_t v = 0; v < shape.positions.size(); ++v) EXPECT_GT(glm::dot(shape.normals[v], shape.positions[v]), 0.0f);
}

TEST(Subdivision, ALoopCageWithQuadsIsDrawnAsItsCageWithAWarning) {
  scene::SubdivisionCage cage = unitCube();
  cage.scheme = scene::SubdivisionScheme::Loop;
  scene::Shape shape;
  std::vector<std::string> warnings;
  scene::subdivide(cage, shape, "stage.usda: /World/Cube", warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("/World/Cube"), std::string::npos);
  EXPECT_NE(warnings[0].find("Loop"), std::string::npos);
  EXPECT_EQ(shape.refinement->level, 0u);
  EXPECT_EQ(shape.vertexCount(), 8u);
  EXPECT_EQ(shape.triangleCount(), 12u);
}

TEST(Subdivision, CreaseAndCornerIndicesPastTheCageWarnAndDrawTheCage) {
  for (int which = 0; which < 2; ++which) {
    scene::SubdivisionCage cage = unitCube();
    if (which == 0) {
      cage.creaseIndices = {0, 80};
      cage.creaseLengths = {2};
      cage.creaseSharpnesses = {1.0f};
    } else {
      cage.cornerIndices = {9};
      cage.cornerSharpnesses = {1.0f};
    }
    scene::Shape shape;
    std::vector<std::string> warnings;
    scene::subdivide(cage, shape, "cube", warnings);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find(which == 0 ? "crease vertex 80" : "corner vertex 9"), std::string::npos) << warnings[0];
    EXPECT_EQ(shape.refinement->level, 0u);
  }
}

TEST(Subdivision, FacesThatAreNotAMeshAreAnErrorNamingTheMesh) {
  auto refuses = [](scene::SubdivisionCage cage, const char* what) {
    scene::Shape shape;
    std::vector<std::string> warnings;
    try {
      scene::subdivide(cage, shape, "stage.usda: /World/Eye", warnings);
      ADD_FAILURE() << "accepted a cage with " << what;
    } catch (const scene::SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("/World/Eye"), std::string::npos) << e.what();
    }
  };
  scene::SubdivisionCage past = unitCube();
  past.faceVertexIndices[5] = 8;
  refuses(past, "an index past its vertices");
  scene::SubdivisionCage counts = unitCube();
  counts.faceVertexCounts[0] = 5;
  refuses(counts, "counts that disagree with its indices");
  scene::SubdivisionCage degenerate = unitCube();
  degenerate.faceVertexCounts = {2, 2, 4, 4, 4, 4, 4};
  refuses(degenerate, "a face of two vertices");
}

TEST(Subdivision, ANonManifoldCageRefinesWithoutFailing) {
  // Three quads sharing one edge (a fin), and a vertex shared by two otherwise separate faces.
  scene::SubdivisionCage cage;
  cage.positions = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, 1, 0}, {0, 0, 1}, {0, 1, 1},
                    {2, 2, 0}, {2, 1, 1}};
  cage.faceVertexIndices = {0, 2, 3, 1, 0, 1, 5, 4, 0, 6, 7, 1, 3, 8, 9};
  cage.faceVertexCounts = {4, 4, 4, 3};
  scene::Shape shape;
  std::vector<std::string> warnings;
  scene::subdivide(cage, shape, "fin", warnings);
  EXPECT_GT(shape.triangleCount(), 0u);
  for (const glm::vec3& p : shape.positions) EXPECT_TRUE(std::isfinite(p.x + p.y + p.z));
  for (const glm::vec3& n : shape.normals) EXPECT_TRUE(std::isfinite(n.x + n.y + n.z));
}

TEST(Subdivision, ALevelPastTheVertexBudgetIsLoweredWithAWarning) {
  scene::SubdivisionCage cage = openGrid(8);  // 64 quads: level 6 would be 2^18 vertices
  cage.level = 6;
  scene::Shape shape;
  std::vector<std::string> warnings;
  scene::subdivide(cage, shape, "grid", warnings, 20000);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("level 6"), std::string::npos) << warnings[0];
  EXPECT_EQ(shape.refinement->level, 4u);  // 64 x 4^3 = 16 384 faces
  EXPECT_LE(shape.vertexCount(), 20000u);
  // And the most levels there are: a level past it is lowered to it (one quad: 4^7 faces at level 8).
  cage = openGrid(1);
  cage.level = 12;
  warnings.clear();
  scene::subdivide(cage, shape, "grid", warnings);
  ASSERT_FALSE(warnings.empty());
  EXPECT_NE(warnings[0].find("lowered to 8"), std::string::npos) << warnings[0];
}

}  // namespace
}  // namespace snell::test
