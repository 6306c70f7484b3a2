// Scenes for the stability grid, built in code so every case is exact and
// small enough to trace on the CPU in double.
#include "ref/refine.h"
#include "scene/procedural_eye.h"
#include "scene/scene_builder.h"
#include "stress/stress.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace snell::stress {

namespace {

scene::Material glass(float ior) {
  scene::Material m = scene::clearGlass("glass", ior);
  m.baseColorFactor = {0.95f, 0.97f, 1.0f, 1.0f};
  return m;
}

scene::Material selfLit(const glm::vec3& colour) {
  scene::Material m;
  m.name = "wall";
  m.baseColorFactor = glm::vec4(colour, 1.0f);
  m.emissiveFactor = colour * 0.8f;
  return m;
}

// A wall of self-lit coloured tiles at z = depth facing +z, `half` wide each
// way: sharp colour edges make any bend of a refracted ray show.
void addBackdrop(scene::Scene& s, float half, float depth) {
  const glm::vec3 colours[4] = {{0.9f, 0.2f, 0.1f}, {0.1f, 0.3f, 0.9f}, {0.95f, 0.85f, 0.2f}, {0.1f, 0.7f, 0.3f}};
  int materials[4];
  for (int i = 0; i < 4; ++i) materials[i] = scene::addMaterial(s, selfLit(colours[i]));
  const int tiles = 8;
  float step = 2.0f * half / tiles;
  for (int i = 0; i < 4; ++i) {
    scene::Shape shape;
    shape.name = "backdrop" + std::to_string(i);
    shape.material = materials[i];
    for (int y = 0; y < tiles; ++y) {
      for (int x = 0; x < tiles; ++x) {
        if ((x + 2 * y) % 4 != i) continue;
        float x0 = -half + float(x) * step, y0 = -half + float(y) * step;
        scene::addQuad(shape, {x0, y0, depth}, {x0 + step, y0, depth}, {x0 + step, y0 + step, depth},
                       {x0, y0 + step, depth});
      }
    }
    scene::addRootShape(s, shape);
  }
}

}  // namespace

scene::Scene placed(scene::Scene s, const glm::vec3& offset, float scale) {
  scene::Node root;
  root.name = "stress placement";
  root.translation = offset;
  root.scale = glm::vec3(scale);
  int index = int(s.nodes.size());
  for (int r : s.roots) {
    s.nodes[size_t(r)].parent = index;
    root.children.push_back(r);
  }
  s.nodes.push_back(root);
  s.roots = {index};
  return s;
}

scene::Scene eyeScene(float ior) {
  // makeEye takes a human range of IORs; the grid also wants ones below 1.
  scene::Scene s = scene::makeEye();
  for (scene::Material& m : s.materials) {
    if (m.refractive()) m.ior = ior;
  }
  addBackdrop(s, 0.03f, -0.02f);
  return s;
}

scene::Scene aqueousEyeScene() {
  scene::EyeOptions options;
  options.aqueous = true;
  scene::Scene s = scene::makeEye(options);
  addBackdrop(s, 0.03f, -0.02f);
  return s;
}

scene::Scene withGlass(scene::Scene s, const std::function<void(scene::Material&)>& change) {
  for (scene::Material& m : s.materials) {
    if (m.refractive()) change(m);
  }
  return s;
}

void addVolume(scene::Material& m, float distance) {
  m.thickness = std::max(m.thickness, 1e-3f * distance);
  m.attenuationColor = {0.75f, 0.88f, 1.0f};
  m.attenuationDistance = distance;
}

void addDispersion(scene::Material& m) { m.dispersion = 1.0f; }  // 20 / Abbe number

void addIorTexture(scene::Material& m, int texture) {
  m.iorTexture.texture = texture;
  m.iorScale = 0.05f;
}

namespace {

// One glass shape (its material the first) over the checker backdrop, as
// most of the grid's cases are.
scene::Scene glassOverBackdrop(const std::string& source, scene::Shape shape, float ior, float half, float depth) {
  scene::Scene s;
  s.source = source;
  shape.material = scene::addMaterial(s, glass(ior));
  scene::addRootShape(s, shape);
  addBackdrop(s, half, depth);
  return s;
}

}  // namespace

scene::Scene sphereScene(uint32_t segments, float ior) {
  return glassOverBackdrop("stress sphere", scene::uvSphere(segments, 1.0f), ior, 3.0f, -3.0f);
}

scene::Scene cubeScene(uint32_t n, float ior) {
  scene::Shape shape;
  shape.name = "cube";
  // Six faces, each an (n+1)^2 vertex grid; the faces' border vertices are
  // welded so that the cube is one closed, indexed surface.
  auto vertex = [&](glm::vec3 p) {
    for (uint32_t i = 0; i < shape.positions.size(); ++i) {
      if (shape.positions[i] == p) return i;
    }
    shape.positions.push_back(p);
    return uint32_t(shape.positions.size() - 1);
  };
  for (int axis = 0; axis < 3; ++axis) {
    for (float side : {-1.0f, 1.0f}) {
      int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (uint32_t i = 0; i < n; ++i) {
        for (uint32_t j = 0; j < n; ++j) {
          auto corner = [&](uint32_t a, uint32_t b) {
            glm::vec3 p(0.0f);
            p[axis] = side;
            p[u] = -1.0f + 2.0f * float(a) / float(n);
            p[v] = -1.0f + 2.0f * float(b) / float(n);
            return vertex(p);
          };
          uint32_t a = corner(i, j), b = corner(i + 1, j), c = corner(i + 1, j + 1), d = corner(i, j + 1);
          // (u, v, axis) is right-handed: counter-clockwise seen from +axis.
          if (side > 0) shape.indices.insert(shape.indices.end(), {a, b, c, a, c, d});
          else shape.indices.insert(shape.indices.end(), {a, c, b, a, d, c});
        }
      }
    }
  }
  // Smooth normals (addShape averages them): flat ones would need split
  // vertices, which open the cube. Near its edges the interpolated normal
  // bends rays as a slightly rounded cube would; both tracers see the same.
  return glassOverBackdrop("stress cube", std::move(shape), ior, 4.0f, -4.0f);
}

scene::Scene slabScene(float thickness, float ior) {
  scene::Shape shape;
  shape.name = "slab";
  float t = thickness;
  glm::vec3 c[8] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {-1, -1, t}, {1, -1, t}, {1, 1, t}, {-1, 1, t}};
  shape.positions.assign(c, c + 8);
  shape.indices = {4, 5, 6, 4, 6, 7,  // top, +z
                   0, 2, 1, 0, 3, 2,  // bottom, -z
                   0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
  // Face normals: the top and bottom must bend the ray as flat glass does.
  shape.normals.assign(8, glm::vec3(0.0f));
  for (int i = 0; i < 4; ++i) shape.normals[size_t(i)] = {0, 0, -1};
  for (int i = 4; i < 8; ++i) shape.normals[size_t(i)] = {0, 0, 1};
  return glassOverBackdrop("stress slab", std::move(shape), ior, 2.0f, -1.0f);
}

scene::Scene degenerateScene() {
  scene::Shape shape;
  shape.name = "degenerate";
  scene::addQuad(shape, {-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {0.5f, 0.5f, 0}, {-0.5f, 0.5f, 0});
  uint32_t n = uint32_t(shape.positions.size());
  // Zero area: three collinear points, and a triangle with a repeated vertex.
  shape.positions.insert(shape.positions.end(), {{-0.4f, 0.1f, 0.2f}, {0.0f, 0.1f, 0.2f}, {0.4f, 0.1f, 0.2f}});
  shape.indices.insert(shape.indices.end(), {n, n + 1, n + 2, n, n, n + 1});
  // Duplicates of the quad's first triangle, same and opposite winding.
  shape.indices.insert(shape.indices.end(), {0, 1, 2, 0, 2, 1});
  // A sliver: 1e-7 high over a unit base.
  uint32_t m = uint32_t(shape.positions.size());
  shape.positions.insert(shape.positions.end(), {{-0.5f, -0.2f, 0.1f}, {0.5f, -0.2f, 0.1f}, {0.0f, -0.2f + 1e-7f, 0.1f}});
  shape.indices.insert(shape.indices.end(), {m, m + 1, m + 2});
  return glassOverBackdrop("stress degenerate triangles", std::move(shape), 1.5f, 1.0f, -1.0f);
}

scene::Scene collapsedScene() {
  scene::Shape shape;
  shape.name = "point";
  shape.positions.assign(30, glm::vec3(0.1f, 0.2f, 0.3f));
  for (uint32_t i = 0; i < 30; ++i) shape.indices.push_back(i);
  return glassOverBackdrop("stress collapsed shape", std::move(shape), 1.5f, 1.0f, -1.0f);
}

scene::Scene gridScene(uint64_t count) {
  scene::Scene s;
  s.source = "stress grid of " + std::to_string(count) + " triangles";
  scene::Material grey;
  grey.baseColorFactor = {0.7f, 0.7f, 0.7f, 1.0f};
  int material = scene::addMaterial(s, grey);
  scene::Shape shape;
  shape.name = "grid";
  shape.material = material;
  uint64_t side = std::max<uint64_t>(1, uint64_t(std::ceil(std::sqrt(double(count)))));
  shape.positions.reserve(size_t(count) * 3);
  shape.indices.reserve(size_t(count) * 3);
  float cell = 2.0f / float(side);
  for (uint64_t t = 0; t < count; ++t) {
    float x = -1.0f + cell * float(t % side), y = -1.0f + cell * float(t / side);
    uint32_t base = uint32_t(shape.positions.size());
    shape.positions.insert(shape.positions.end(), {{x, y, 0}, {x + 0.8f * cell, y, 0}, {x, y + 0.8f * cell, 0}});
    shape.indices.insert(shape.indices.end(), {base, base + 1, base + 2});
  }
  shape.normals.assign(shape.positions.size(), glm::vec3(0, 0, 1));
  scene::addRootShape(s, shape);
  return s;
}

scene::Scene morphingSphereScene(float ior) {
  scene::Scene s;
  s.source = "stress morphing sphere";
  scene::Shape shape = scene::uvSphere(32, 1.0f);
  shape.material = scene::addMaterial(s, glass(ior));
  scene::MorphTarget squash, insideOut;
  for (const glm::vec3& p : shape.positions) {
    squash.positions.push_back({0.0f, 0.0f, -0.99f * p.z});
    insideOut.positions.push_back(-2.0f * p);
  }
  shape.targets = {squash, insideOut};
  scene::addRootShape(s, shape);
  addBackdrop(s, 3.0f, -3.0f);
  return s;
}

scene::SubdivisionCage corneaCage(uint32_t rings, uint32_t segments, float radius, float height, uint32_t level) {
  scene::SubdivisionCage cage;
  cage.level = level;
  cage.limitSurface = true;
  const double pi = 3.14159265358979323846, R = radius, h = height;
  const double rim = std::sqrt(2.0 * R * h - h * h), centreZ = h - R;  // the sphere's centre is below the base
  const double rimAngle = std::asin(rim / R);                          // from the apex, about the centre
  // Vertices: the apex, then `rings` rings on the cap down to the rim, then
  // the base's rings inwards, then the base's centre.
  auto at = [&](uint32_t ring, uint32_t k) { return 1 + (ring - 1) * segments + k % segments; };
  cage.positions.push_back({0.0f, 0.0f, float(h)});
  for (uint32_t r = 1; r <= rings; ++r) {
    double a = rimAngle * double(r) / double(rings);
    for (uint32_t k = 0; k < segments; ++k) {
      double phi = 2.0 * pi * double(k) / double(segments);
      cage.positions.push_back(glm::vec3(glm::dvec3(R * std::sin(a) * std::cos(phi), R * std::sin(a) * std::sin(phi),
                                                    centreZ + R * std::cos(a))));
    }
  }
  const uint32_t baseRings = 2;
  for (uint32_t r = 1; r <= baseRings; ++r) {
    double radiusHere = rim * double(baseRings + 1 - r) / double(baseRings + 1);
    for (uint32_t k = 0; k < segments; ++k) {
      double phi = 2.0 * pi * double(k) / double(segments);
      cage.positions.push_back(glm::vec3(glm::dvec3(radiusHere * std::cos(phi), radiusHere * std::sin(phi), 0.0)));
    }
  }
  const uint32_t centre = uint32_t(cage.positions.size());
  cage.positions.push_back({0.0f, 0.0f, 0.0f});
  // Faces, counter-clockwise seen from outside: the apex fan, the cap's quads, the base's quads and fan.
  for (uint32_t k = 0; k < segments; ++k) {
    cage.faceVertexIndices.insert(cage.faceVertexIndices.end(), {0, at(1, k), at(1, k + 1)});
    cage.faceVertexCounts.push_back(3);
  }
  for (uint32_t r = 1; r < rings + baseRings; ++r) {
    for (uint32_t k = 0; k < segments; ++k) {
      cage.faceVertexIndices.insert(cage.faceVertexIndices.end(), {at(r, k), at(r + 1, k), at(r + 1, k + 1), at(r, k + 1)});
      cage.faceVertexCounts.push_back(4);
    }
  }
  for (uint32_t k = 0; k < segments; ++k) {
    cage.faceVertexIndices.insert(cage.faceVertexIndices.end(),
                                  {at(rings + baseRings, k), centre, at(rings + baseRings, k + 1)});
    cage.faceVertexCounts.push_back(3);
  }
  for (uint32_t k = 0; k <= segments; ++k) cage.creaseIndices.push_back(at(rings, k));
  cage.creaseLengths = {segments + 1};
  cage.creaseSharpnesses = {10.0f};  // infinitely sharp: the rim stays a circle, the base flat
  if (level == 0) return cage;

  // Fit: the cage whose limit surface lies closest to the lens, in least
  // squares over every refined vertex. The refined vertices are a linear map
  // A of the cage (its columns: the refinement of a cage of one unit
  // vertex), so each round projects them onto the lens (the cap, the rim
  // circle or the base, by where they lie) and solves A^T A c = A^T target.
  scene::Shape shape;
  std::vector<std::string> warnings;
  scene::subdivide(cage, shape, "cornea cage", warnings);
  const scene::Refinement& r = *shape.refinement;
  const size_t n = cage.positions.size(), m = r.vertexOf.size();
  std::vector<double> columns(n * m);  // A, column after column
  std::vector<glm::dvec3> unitCage(n, glm::dvec3(0.0)), refined, normals;
  for (size_t i = 0; i < n; ++i) {
    unitCage[i].x = 1.0;
    ref::refineOnCpu(r, unitCage, refined, normals);
    for (size_t j = 0; j < m; ++j) columns[i * m + j] = refined[j].x;
    unitCage[i].x = 0.0;
  }
  std::vector<double> normal(n * n, 0.0);  // A^T A, then its Cholesky factor
  for (size_t i = 0; i < n; ++i) {
    for (size_t k = 0; k <= i; ++k) {
      double sum = 0.0;
      for (size_t j = 0; j < m; ++j) sum += columns[i * m + j] * columns[k * m + j];
      normal[i * n + k] = normal[k * n + i] = sum;
    }
  }
  for (size_t i = 0; i < n; ++i) {
    for (size_t k = 0; k <= i; ++k) {
      double sum = normal[i * n + k];
      for (size_t q = 0; q < k; ++q) sum -= normal[i * n + q] * normal[k * n + q];
      normal[i * n + k] = i == k ? std::sqrt(sum) : sum / normal[k * n + k];
    }
  }
  // Each refined vertex's part of the lens, from the cage as built (the base
  // is flat, z = 0, and the cap above it): the rim is the base's vertices
  // that share a triangle with the cap's.
  enum Part { kCap, kBase, kRim };
  std::vector<Part> part(m);
  for (size_t j = 0; j < m; ++j) part[j] = shape.positions[j].z > 1e-6f ? kCap : kBase;
  for (size_t t = 0; t + 2 < shape.indices.size(); t += 3) {
    const uint32_t* c = &shape.indices[t];
    bool cap = part[c[0]] == kCap || part[c[1]] == kCap || part[c[2]] == kCap;
    for (int k = 0; k < 3 && cap; ++k) part[c[k]] = part[c[k]] == kCap ? kCap : kRim;
  }
  auto onLens = [&](size_t j, const glm::dvec3& p) {
    const double planar = std::max(std::hypot(p.x, p.y), 1e-30);
    if (part[j] == kBase) return glm::dvec3(p.x, p.y, 0.0);
    if (part[j] == kRim) return glm::dvec3(p.x * rim / planar, p.y * rim / planar, 0.0);
    glm::dvec3 c(0.0, 0.0, centreZ);
    return c + R * glm::normalize(p - c);
  };
  std::vector<glm::dvec3> points(cage.positions.begin(), cage.positions.end());
  for (int round = 0; round < 12; ++round) {
    ref::refineOnCpu(r, points, refined, normals);
    std::vector<glm::dvec3> rhs(n, glm::dvec3(0.0));  // A^T target
    for (size_t j = 0; j < m; ++j) {
      glm::dvec3 target = onLens(j, refined[j]);
      for (size_t i = 0; i < n; ++i) rhs[i] += columns[i * m + j] * target;
    }
    for (size_t i = 0; i < n; ++i) {  // L y = rhs, then L^T c = y
      for (size_t k = 0; k < i; ++k) rhs[i] -= normal[i * n + k] * rhs[k];
      rhs[i] /= normal[i * n + i];
    }
    for (size_t i = n; i-- > 0;) {
      for (size_t k = i + 1; k < n; ++k) rhs[i] -= normal[k * n + i] * rhs[k];
      rhs[i] /= normal[i * n + i];
    }
    points = rhs;
  }
  for (size_t v = 0; v < points.size(); ++v) cage.positions[v] = glm::vec3(points[v]);
  return cage;
}

scene::Scene subdividedCorneaScene(uint32_t level, bool creased, uint32_t rings, uint32_t segments) {
  scene::Scene s;
  s.source = "stress subdivided cornea";
  scene::Shape shape;
  shape.name = "cornea";
  std::vector<std::string> warnings;
  scene::SubdivisionCage cage = corneaCage(rings, segments, 1.0f, 0.5f, std::min(level, 2u));
  cage.level = level;
  if (!creased) cage.creaseIndices.clear(), cage.creaseLengths.clear(), cage.creaseSharpnesses.clear();
  scene::subdivide(cage, shape, "cornea", warnings);
  shape.material = scene::addMaterial(s, glass(1.376f));
  scene::addRootShape(s, shape);
  addBackdrop(s, 2.0f, -1.0f);
  return s;
}

scene::Scene nonFiniteMorphScene(uint32_t& poisonedTriangles) {
  scene::Scene s;
  s.source = "stress non-finite deformation";
  scene::Shape shape = scene::uvSphere(24, 1.0f);
  shape.material = scene::addMaterial(s, glass(1.5f));
  scene::MorphTarget poison;
  poison.positions.assign(shape.positions.size(), glm::vec3(0.0f));
  // A band of vertices in the upper half goes to NaN, one vertex to infinity.
  for (size_t v = 0; v < shape.positions.size(); ++v) {
    if (shape.positions[v].z > 0.55f && shape.positions[v].z < 0.7f) poison.positions[v].x = std::numeric_limits<float>::quiet_NaN();
  }
  poison.positions[shape.positions.size() / 2].y = std::numeric_limits<float>::infinity();
  poisonedTriangles = 0;
  for (size_t t = 0; t < shape.indices.size(); t += 3) {
    bool bad = false;
    for (int k = 0; k < 3; ++k) {
      const glm::vec3& d = poison.positions[shape.indices[t + size_t(k)]];
      bad = bad || !std::isfinite(d.x) || !std::isfinite(d.y);
    }
    poisonedTriangles += bad ? 1 : 0;
  }
  shape.targets = {poison};
  scene::addRootShape(s, shape);
  s.meshes.back().weights = {1.0f};
  addBackdrop(s, 3.0f, -3.0f);
  return s;
}

}  // namespace snell::stress
