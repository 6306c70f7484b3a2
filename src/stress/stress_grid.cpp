// The stability grid: which cases, and how one case is rendered twice (GPU,
// CPU reference) and compared.
#include "io/image_file.h"
#include "ref/reference_tracer.h"
#include "render/bvh.h"
#include "render/one_view.h"
#include "render/renderer.h"
#include "stress/stress.h"
#include "vk/commands.h"

#include <glm/gtc/constants.hpp>

#include <chrono>
#include <map>
#include <set>
#include <cmath>
#include <random>
#include <stdexcept>

namespace snell::stress {

namespace {

constexpr double kDegree = glm::pi<double>() / 180.0;
// A self-hit's segment is rounding's length; a path's own are features'. In
// the edges group a ray through the cube's box corners came back in through
// the face across the edge 2e-6 to 6e-6 after leaving (its shortest segment,
// against 1.3 to 2.1 for the reference's); the aqueous eye's one "self-hit"
// was green light passing outside the iris's rim, which the reference's met
// (shortest segments 0.6 mm both).
constexpr double kSelfHitShare = 0.01;

using ViewFn = std::function<scene::View(const scene::Scene&, const scene::Pose&)>;

ViewFn lookAt(glm::dvec3 eye, glm::dvec3 target, double yfov) {
  return [=](const scene::Scene& s, const scene::Pose& pose) {
    scene::ViewRequest request;
    request.lookAt = scene::LookAt{eye, target, {0.0, 1.0, 0.0}};
    request.yfov = yfov;
    return scene::resolveView(s, pose, request);
  };
}

// The eye seen from `degrees` off the cornea's axis, after placed(offset, scale).
ViewFn eyeView(double degrees, glm::dvec3 offset = glm::dvec3(0.0), double scale = 1.0) {
  double a = degrees * kDegree;
  glm::dvec3 eye = offset + scale * glm::dvec3(0.045 * std::sin(a), 0.0, 0.045 * std::cos(a));
  return lookAt(eye, offset + scale * glm::dvec3(0.0, 0.0, 0.006), 0.5);
}

// A triangle in world space, and which of its edges (v[k], v[k+1]) and
// corners are inside its shape's surface: shared with a neighbour, not on a
// border, where a ray may pass either side of the edge in either precision.
struct WorldTriangle {
  std::array<glm::dvec3, 3> v;
  std::array<bool, 3> sharedEdge{}, innerCorner{};
};

// World-space triangles of the shapes whose name passes `wanted`, at the pose.
std::vector<WorldTriangle> worldTriangles(const scene::Scene& s, const scene::Pose& pose,
                                          const std::function<bool(const std::string&)>& wanted) {
  std::vector<WorldTriangle> triangles;
  for (const scene::DrawItem& item : pose.items) {
    const scene::Shape& shape = s.shapes[size_t(item.shape)];
    if (!wanted(shape.name)) continue;
    std::vector<glm::dvec3> positions, normals;
    scene::deformOnCpu(item, positions, normals);
    glm::dmat4 world(item.world);
    std::map<std::pair<uint32_t, uint32_t>, int> edgeUses;
    auto key = [](uint32_t a, uint32_t b) { return std::make_pair(std::min(a, b), std::max(a, b)); };
    for (size_t t = 0; t + 2 < shape.indices.size(); t += 3) {
      for (size_t k = 0; k < 3; ++k) ++edgeUses[key(shape.indices[t + k], shape.indices[t + (k + 1) % 3])];
    }
    std::set<uint32_t> borderVertices;
    for (const auto& [edge, uses] : edgeUses) {
      if (uses != 2) borderVertices.insert({edge.first, edge.second});
    }
    for (size_t t = 0; t + 2 < shape.indices.size(); t += 3) {
      WorldTriangle tri;
      for (size_t k = 0; k < 3; ++k) {
        uint32_t a = shape.indices[t + k], b = shape.indices[t + (k + 1) % 3];
        tri.v[k] = glm::dvec3(world * glm::dvec4(positions[a], 1.0));
        tri.sharedEdge[k] = edgeUses[key(a, b)] == 2;
        tri.innerCorner[k] = borderVertices.count(a) == 0;
      }
      triangles.push_back(tri);
    }
  }
  return triangles;
}

using AimFn = std::function<void(const scene::Scene&, const scene::Pose&, std::vector<scene::Ray>&, std::vector<double>&)>;
using BoxAimFn = std::function<void(const scene::Scene&, const scene::Pose&, const std::vector<std::array<float, 6>>&,
                                    std::vector<scene::Ray>&, std::vector<double>&)>;

// Where an aimed ray starts, given the aimed point, the unit geometric normal
// of the triangle it was taken from, and the ray's index.
using OriginFn = std::function<glm::dvec3(const glm::dvec3& p, const glm::dvec3& normal, size_t i)>;

// Rays aimed at points exactly on shared edges and at shared vertices (in
// double, so in float they fall within rounding of the edge: the case that
// leaks when neighbouring triangles disagree). Origins come from `origin`.
void aimAtEdges(const std::vector<WorldTriangle>& triangles, size_t count, const OriginFn& origin,
                std::vector<scene::Ray>& rays, std::vector<double>& distances) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  rays.resize(count);
  distances.resize(count);
  size_t next = 0;
  for (size_t i = 0; i < count; ++i) {
    // A vertex, a midpoint, or anywhere on an edge, in turn; border edges and
    // corners are skipped, and so are rays within 75 degrees of grazing the
    // face (a ray that only touches a surface may miss it in either precision).
    int what = int(i % 3);
    bool found = false;
    for (size_t tries = 0; tries < 6 * triangles.size() && !found; ++tries, ++next) {
      const WorldTriangle& tri = triangles[(next * 7919) % triangles.size()];
      size_t edge = next % 3;
      if (what == 0 && tries == 3 * triangles.size()) what = 2;  // no inner corner anywhere: an edge instead
      if (!(what == 0 ? tri.innerCorner[edge] : tri.sharedEdge[edge])) continue;
      const glm::dvec3 &a = tri.v[edge], &b = tri.v[(edge + 1) % 3];
      double t = what == 0 ? 0.0 : what == 1 ? 0.5 : u(rng);
      glm::dvec3 p = a + t * (b - a);
      glm::dvec3 normal = glm::normalize(glm::cross(tri.v[1] - tri.v[0], tri.v[2] - tri.v[0]));
      glm::dvec3 o = origin(p, normal, i);
      glm::dvec3 d = glm::normalize(p - o);
      if (!(std::abs(glm::dot(d, normal)) >= 0.25)) continue;
      rays[i] = {o, d};
      distances[i] = glm::length(p - o);
      found = true;
    }
    if (!found) throw std::logic_error("stress: no shared edge to aim at");
  }
}

// Origins outside a convex mesh around `centre`, on the line from the centre
// through the aimed point, tilted by up to 19 degrees: every ray goes into the
// body after its aimed point, so none merely touches an edge or a corner
// (a touching ray may graze or miss in either precision).
OriginFn fromCentre(glm::dvec3 centre, double distance) {
  return [=](const glm::dvec3& p, const glm::dvec3&, size_t i) {
    glm::dvec3 out = glm::normalize(p - centre);
    std::mt19937_64 rng(i);
    std::normal_distribution<double> n(0.0, 0.2);
    glm::dvec3 jitter(n(rng), n(rng), n(rng));
    jitter -= glm::dot(jitter, out) * out;
    if (glm::length(jitter) > 0.35) jitter *= 0.35 / glm::length(jitter);
    return p + distance * glm::normalize(out + jitter);
  };
}

// Rays through the trees' own boxes: each passes exactly through a corner, a
// point on an edge or a point on a face of a child box of the shape's tree
// (group 0: the scene's first shape), on its way to a point well inside one
// of the shape's triangles that it meets at least 15 degrees off grazing, so
// it crosses the surface rather than touching it. With `axisRays`, every
// fourth ray instead runs parallel to an axis through a box corner (its
// direction has two zero components, the slab test's stand-in case); for the
// unit sphere of sphereScene, only those whose line passes at least 0.05 from
// its surface (a tangent ray may touch or miss in either precision), starting
// 2 from its centre, aimed at no surface (distance -1).
BoxAimFn aimAtBoxes(double distance, bool axisRays) {
  return [=](const scene::Scene& s, const scene::Pose& pose, const std::vector<std::array<float, 6>>& all,
             std::vector<scene::Ray>& rays, std::vector<double>& distances) {
    std::vector<std::array<float, 6>> boxes;
    for (const auto& b : all) {
      if (b[0] <= b[3] && b[1] <= b[4] && b[2] <= b[5]) boxes.push_back(b);  // empty children hold nothing
    }
    auto triangles = worldTriangles(s, pose, [](const std::string& n) { return n.rfind("backdrop", 0) != 0; });
    if (boxes.empty() || triangles.empty()) throw std::logic_error("stress: no boxes or triangles to aim at");
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    distances.assign(rays.size(), -1.0);
    for (size_t i = 0; i < rays.size(); ++i) {
      for (size_t tries = 0;; ++tries) {
        if (tries > 1000) throw std::logic_error("stress: no ray through a box found");
        const auto& b = boxes[size_t(rng() % boxes.size())];
        glm::dvec3 lo(b[0], b[1], b[2]), hi(b[3], b[4], b[5]);
        // Per axis the low face, the high face, or (an edge's or a face's free axes) anywhere between.
        int what = int(i % 4), free = int(rng() % 3);
        glm::dvec3 c;
        for (int axis = 0; axis < 3; ++axis) {
          bool between = (what == 1 && axis == free) || (what == 2 && axis != free);
          c[axis] = between ? lo[axis] + u(rng) * (hi[axis] - lo[axis]) : (rng() % 2 ? hi[axis] : lo[axis]);
        }
        if (what == 3 && axisRays) {
          glm::dvec3 d(0.0);
          d[free] = rng() % 2 ? 1.0 : -1.0;
          glm::dvec3 across = c - glm::dot(c, d) * d;  // from the centre to the line
          if (std::abs(glm::length(across) - 1.0) < 0.05) continue;
          rays[i] = {across - 2.0 * d, d};  // from outside the sphere, before the backdrop (at 3)
          break;
        }
        const WorldTriangle& tri = triangles[size_t(rng() % triangles.size())];
        double b1 = u(rng), b2 = u(rng);
        if (b1 + b2 > 1.0) b1 = 1.0 - b1, b2 = 1.0 - b2;
        b1 = 0.1 + 0.7 * b1, b2 = 0.1 + 0.7 * b2;  // every barycentric at least 0.1: well inside every edge
        glm::dvec3 q = (1.0 - b1 - b2) * tri.v[0] + b1 * tri.v[1] + b2 * tri.v[2];
        glm::dvec3 normal = glm::normalize(glm::cross(tri.v[1] - tri.v[0], tri.v[2] - tri.v[0]));
        if (!(glm::length(q - c) > 1e-3)) continue;
        glm::dvec3 d = glm::normalize(q - c);
        if (!(std::abs(glm::dot(d, normal)) >= 0.25)) continue;
        rays[i] = {c - distance * d, d};
        distances[i] = distance + glm::length(q - c);
        break;
      }
    }
  };
}

// Rays that graze the faces of the cube of cubeScene: aimed at points of the
// top face's inner shared edges (where two of its coplanar triangles meet) at
// 0.05 to 3 degrees above the face; every fifth ray runs parallel to the face
// 1e-4 above it and must not touch it (aimed distance -1).
AimFn grazeTheCube(double distance) {
  return [=](const scene::Scene& s, const scene::Pose& pose, std::vector<scene::Ray>& rays,
             std::vector<double>& distances) {
    std::vector<std::pair<glm::dvec3, glm::dvec3>> edges;  // inner shared edges of the top face
    for (const WorldTriangle& tri : worldTriangles(s, pose, [](const std::string& n) { return n == "cube"; })) {
      for (size_t k = 0; k < 3; ++k) {
        const glm::dvec3 &a = tri.v[k], &b = tri.v[(k + 1) % 3];
        auto inner = [](const glm::dvec3& v) { return v.y == 1.0 && std::abs(v.x) < 0.99 && std::abs(v.z) < 0.99; };
        if (tri.sharedEdge[k] && inner(a) && inner(b)) edges.emplace_back(a, b);
      }
    }
    if (edges.empty()) throw std::logic_error("stress: the cube's top face has no inner edge");
    const double angles[] = {0.05, 0.2, 1.0, 3.0};
    std::mt19937_64 rng(13);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    distances.resize(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) {
      const auto& [a, b] = edges[(i * 7919) % edges.size()];
      glm::dvec3 p = a + u(rng) * (b - a);
      double phi = 2.0 * glm::pi<double>() * u(rng);
      glm::dvec3 along(std::cos(phi), 0.0, std::sin(phi));
      if (i % 5 == 4) {  // parallel, just above: it crosses the whole face without touching it
        p.y += 1e-4;
        rays[i] = {p - distance * along, along};
        distances[i] = -1.0;
        continue;
      }
      double theta = angles[i % 5 % 4] * kDegree;
      glm::dvec3 d = std::cos(theta) * along - std::sin(theta) * glm::dvec3(0.0, 1.0, 0.0);
      rays[i] = {p - distance * d, d};
      distances[i] = distance;
    }
  };
}

Case image(std::string name, std::string group, std::function<scene::Scene()> make, ViewFn view,
           const GridOptions& o, int maxError, double overOneShare = 0.002) {
  Case c;
  c.name = std::move(name);
  c.group = std::move(group);
  c.makeScene = std::move(make);
  c.view = std::move(view);
  c.width = o.imageWidth;
  c.height = o.imageHeight;
  c.maxError = maxError;
  c.overOneShare = overOneShare;
  return c;
}

Case aimed(std::string name, std::string group, std::function<scene::Scene()> make, ViewFn view, const GridOptions& o,
           AimFn aim, bool closed) {
  // Aimed rays are about leaks and self-hits: their colours are compared with
  // a loose bound, since rays aimed at one edge land side by side on the backdrop's tile borders.
  Case c = image(std::move(name), std::move(group), std::move(make), std::move(view), o, 255, 0.03);
  c.kind = Kind::AimedRays;
  c.width = c.height = o.aimedRaysSide;
  c.aim = std::move(aim);
  c.closed = closed;
  return c;
}

}  // namespace

std::vector<Case> grid(const GridOptions& o) {
  std::vector<Case> cases;
  // Far from the origin: the eye and its camera moved together. The rebase to
  // camera-relative coordinates must keep the error where it is at the origin.
  for (double d : {0.0, 1e2, 1e4, 1e5, 1e6}) {
    glm::vec3 offset{float(d)};
    std::string name = d == 0.0 ? "far: at the origin" : "far: moved by " + std::to_string(int64_t(d));
    cases.push_back(image(name, "far", [=] { return placed(eyeScene(1.376f), offset, 1.0f); },
                          eyeView(20.0, glm::dvec3(offset), 1.0), o, 8));
  }
  for (double s : {1e-4, 1e-2, 1e2, 1e4}) {
    char name[64];
    std::snprintf(name, sizeof name, "scale: eye x %g", s);
    cases.push_back(image(name, "scale", [=] { return placed(eyeScene(1.376f), glm::vec3(0.0f), float(s)); },
                          eyeView(20.0, glm::dvec3(0.0), s), o, 8));
  }
  for (double a : {45.0, 75.0, 85.0, 89.0, 89.9}) {
    char name[64];
    std::snprintf(name, sizeof name, "grazing: %g degrees off the cornea's axis", a);
    cases.push_back(image(name, "grazing", [] { return eyeScene(1.376f); }, eyeView(a), o, 255, 0.01));
  }
  for (float ior : {1.0f, 1.0001f, 1.33f, 1.376f, 2.42f, 4.0f, 0.75f}) {
    char name[64];
    std::snprintf(name, sizeof name, ior < 1.0f ? "ior: cornea %g (below its surroundings)" : "ior: cornea %g", ior);
    cases.push_back(image(name, "ior", [=] { return eyeScene(ior); }, eyeView(20.0), o, 8));
  }
  cases.push_back(image("ior: total internal reflection in a 2.42 slab", "ior", [] { return slabScene(0.5f, 2.42f); },
                        lookAt({2.2, 0.3, 1.7}, {0.0, 0.0, 0.25}, 0.9), o, 8));
  cases.push_back(image("ior: slab of 0.75 (less dense than its surroundings)", "ior",
                        [] { return slabScene(0.5f, 0.75f); }, lookAt({2.2, 0.3, 1.7}, {0.0, 0.0, 0.25}, 0.9), o, 8));

  // Watertightness: rays aimed at shared edges and vertices of closed meshes (IOR 1 and glass).
  // From outside, towards a point inside the (convex) mesh: every aimed ray crosses its surface.
  auto aimAt = [](double distance, glm::dvec3 inside = glm::dvec3(0.0)) {
    return [=](const scene::Scene& s, const scene::Pose& pose, std::vector<scene::Ray>& rays, std::vector<double>& d) {
      auto tris = worldTriangles(s, pose, [](const std::string& n) { return n.rfind("backdrop", 0) != 0; });
      aimAtEdges(tris, rays.size(), fromCentre(inside, distance), rays, d);
    };
  };
  ViewFn sphereView = lookAt({0.0, 0.3, 4.0}, {0.0, 0.0, 0.0}, 0.8);
  for (float ior : {1.0f, 1.5f}) {
    std::string suffix = ior == 1.0f ? " (IOR 1)" : " (IOR 1.5)";
    cases.push_back(aimed("watertight: sphere" + suffix, "watertight", [=] { return sphereScene(48, ior); }, sphereView,
                          o, aimAt(3.0), ior == 1.0f));
    cases.push_back(aimed("watertight: cube" + suffix, "watertight", [=] { return cubeScene(6, ior); }, sphereView, o,
                          aimAt(3.0), ior == 1.0f));
    cases.back().countSelfHits = ior == 1.0f;
  }
  // A cornea refined from a coarse Catmull-Clark cage (two levels on the GPU's
  // tables): its refined triangles are as watertight as any mesh, and it
  // draws as the reference draws it.
  cases.push_back(aimed("watertight: a dome refined from its subdivision cage, rim uncreased (IOR 1)", "watertight",
                        [] { return withGlass(subdividedCorneaScene(2, false), [](scene::Material& m) { m.ior = 1.0f; }); },
                        sphereView, o, aimAt(3.0, {0.0, 0.0, 0.2}), true));
  cases.push_back(image("subdivided: a cornea refined twice from a Catmull-Clark cage of 48 faces", "subdivided",
                        [] { return subdividedCorneaScene(2); }, lookAt({0.6, 0.5, 2.4}, {0.0, 0.0, 0.25}, 0.9), o, 8));
  cases.push_back(aimed("watertight: the eye's surfaces from the camera", "watertight",
                        [] { return eyeScene(1.376f); }, eyeView(20.0), o,
                        [](const scene::Scene& s, const scene::Pose& pose, std::vector<scene::Ray>& rays,
                           std::vector<double>& d) {
                          scene::View v = eyeView(20.0)(s, pose);
                          auto tris = worldTriangles(s, pose, [](const std::string& n) { return n.rfind("backdrop", 0) != 0; });
                          aimAtEdges(tris, rays.size(), [&](const glm::dvec3&, const glm::dvec3&, size_t) { return v.eye; },
                                     rays, d);
                        },
                        false));

  // Edges and corners, each aimed ray's first hit held to the reference's:
  // shared edges and vertices of a finer sphere, the corners, edges and faces
  // of the boxes the walk tests (axis-parallel rays among them), and rays
  // grazing a flat face or running parallel just above it.
  auto edgesCase = [&](std::string name, std::function<scene::Scene()> make, AimFn aim, bool closed) {
    cases.push_back(aimed("edges: " + name, "edges", std::move(make), sphereView, o, std::move(aim), closed));
    cases.back().countMissedHits = true;
  };
  edgesCase("shared edges and vertices of a sphere of 20000 triangles (IOR 1)", [] { return sphereScene(100, 1.0f); },
            aimAt(3.0), true);
  edgesCase("through corners, edges and faces of the sphere's tree boxes (IOR 1)",
            [] { return sphereScene(48, 1.0f); }, nullptr, true);
  cases.back().aimAtBoxes = aimAtBoxes(3.0, true);
  edgesCase("through corners, edges and faces of the cube's tree boxes (IOR 1)", [] { return cubeScene(6, 1.0f); },
            nullptr, true);
  cases.back().aimAtBoxes = aimAtBoxes(3.0, false);
  edgesCase("grazing the cube's face at 0.05 to 3 degrees, and parallel 1e-4 above it (IOR 1)",
            [] { return cubeScene(6, 1.0f); }, grazeTheCube(4.0), true);

  // Self-intersection: thin slabs, rays through the top face's edges at an angle.
  for (float thickness : {1e-2f, 1e-3f, 1e-4f, 1e-5f}) {
    char name[64];
    std::snprintf(name, sizeof name, "self-hit: slab %g thick", thickness);
    cases.push_back(aimed(name, "self-hit", [=] { return slabScene(thickness, 1.5f); },
                          lookAt({0.5, 0.4, 2.0}, {0.0, 0.0, 0.0}, 0.9), o,
                          [](const scene::Scene& s, const scene::Pose& pose, std::vector<scene::Ray>& rays,
                             std::vector<double>& d) {
                            auto tris = worldTriangles(s, pose, [](const std::string& n) { return n == "slab"; });
                            // The top face's diagonal: the slab's rim edges would be touched, not crossed.
                            tris.resize(2);
                            tris[0].sharedEdge = {false, false, true};
                            tris[1].sharedEdge = {true, false, false};
                            tris[0].innerCorner = tris[1].innerCorner = {false, false, false};
                            aimAtEdges(tris, rays.size(),
                                       [](const glm::dvec3& p, const glm::dvec3&, size_t i) {
                                         double a = 0.3 + 0.9 * double(i % 97) / 97.0, phi = double(i % 13);
                                         return p + 2.0 * glm::dvec3(std::sin(a) * std::cos(phi), std::sin(a) * std::sin(phi), std::cos(a));
                                       },
                                       rays, d);
                          },
                          false));  // glass: internal reflections at the rim count as crossings too
  }

  // Degenerate input.
  ViewFn front = lookAt({0.1, 0.2, 2.5}, {0.0, 0.0, 0.0}, 0.8);
  // A duplicated refractive triangle is two faces at one distance: which one a
  // ray meets first, and whether it then meets the other, is up to rounding
  // in both tracers (as with GlassVaseFlowers' coincident faces).
  cases.push_back(image("degenerate: zero-area, duplicate and sliver triangles", "degenerate", degenerateScene, front, o, 255, 0.1));
  cases.push_back(image("degenerate: a shape collapsed to one point", "degenerate", collapsedScene, front, o, 8));
  cases.push_back(image("degenerate: 0 triangles", "degenerate", [] { return gridScene(0); }, front, o, 8));
  cases.push_back(image("degenerate: 1 triangle", "degenerate", [] { return gridScene(1); }, front, o, 8));
  {
    uint32_t poisoned = 0;
    nonFiniteMorphScene(poisoned);
    Case c = image("degenerate: NaN and infinite positions from a morph", "degenerate",
                   [] {
                     uint32_t unused = 0;
                     return nonFiniteMorphScene(unused);
                   },
                   sphereView, o, 8);
    c.expectDropped = poisoned;
    cases.push_back(c);
  }
  if (o.huge) {
    cases.push_back(image("degenerate: 10^7 triangles", "degenerate", [] { return gridScene(10'000'000); },
                          lookAt({0.0, 0.0, 2.5}, {0.0, 0.0, 0.0}, 0.8), o, 255, 0.05));
  }

  // Extreme deformation: squashed to 1% of its depth, then turned inside out, refit every frame.
  {
    // Squashed flat, its rim is seen edge-on: a few silhouette pixels flip.
    Case c = image("deform: sphere squashed to 1% then inside out, 12 refits", "deform",
                   [] { return morphingSphereScene(1.5f); }, sphereView, o, 255, 0.002);
    c.frames = 12;
    c.morph = [](scene::Pose& pose, uint32_t f) {
      for (scene::DrawItem& item : pose.items) {
        if (item.weights.size() != 2) continue;
        double t = double(f) / 11.0;  // 0..1: squash in, then through the centre
        item.weights = {float(std::min(1.0, 2.0 * t)), float(std::max(0.0, 2.0 * t - 1.0))};
      }
    };
    cases.push_back(c);
  }

  // Optics: every feature of shaders/shared/trace.h on the eye, alone and all
  // together far from the origin; aimed rays through nested and dispersive
  // glass, where the reference also checks R + T = 1 at every boundary.
  {
    auto eye = [] { return eyeScene(1.376f); };
    auto volume = [](scene::Material& m) { addVolume(m, 0.004f); };  // 4 mm: the eye's scale
    auto iorTexture = [](scene::Material& m) { addIorTexture(m, 0); };  // the iris texture
    auto all = [=](scene::Material& m) { volume(m), addDispersion(m), iorTexture(m); };
    scene::Optics noFresnel, sky;
    noFresnel.fresnel = false;
    sky.environment = std::make_shared<scene::Environment>(scene::proceduralSky(256));
    sky.reflections = 4;
    auto opticsCase = [&](std::string name, std::function<scene::Scene()> make, ViewFn view, scene::Optics optics) {
      cases.push_back(image("optics: " + name, "optics", std::move(make), std::move(view), o, 8));
      cases.back().optics = std::move(optics);
    };
    opticsCase("Fresnel off", eye, eyeView(20.0), noFresnel);
    opticsCase("HDR sky, 4 reflections, 60 degrees", eye, eyeView(60.0), sky);
    opticsCase("volume", [=] { return withGlass(eyeScene(1.376f), volume); }, eyeView(20.0), {});
    opticsCase("dispersion", [=] { return withGlass(eyeScene(1.376f), addDispersion); }, eyeView(20.0), {});
    opticsCase("IOR texture", [=] { return withGlass(eyeScene(1.376f), iorTexture); }, eyeView(20.0), {});
    opticsCase("aqueous nested in the cornea", aqueousEyeScene, eyeView(20.0), {});
    glm::vec3 far(1e4f);
    opticsCase("all, moved by 10000", [=] { return placed(withGlass(aqueousEyeScene(), all), far, 1.0f); },
               eyeView(45.0, glm::dvec3(far)), sky);
    auto throughEdges = [](ViewFn view) {
      return [=](const scene::Scene& s, const scene::Pose& pose, std::vector<scene::Ray>& rays, std::vector<double>& d) {
        scene::View v = view(s, pose);
        auto tris = worldTriangles(s, pose, [](const std::string& n) { return n.rfind("backdrop", 0) != 0; });
        aimAtEdges(tris, rays.size(), [&](const glm::dvec3&, const glm::dvec3&, size_t) { return v.eye; }, rays, d);
      };
    };
    cases.push_back(aimed("optics: aimed rays through the aqueous eye, all features", "optics",
                          [=] { return withGlass(aqueousEyeScene(), all); }, eyeView(20.0), o,
                          throughEdges(eyeView(20.0)), false));
    cases.back().optics = sky;
    cases.push_back(aimed("optics: aimed rays into a dispersive, absorbing sphere", "optics",
                          [] { return withGlass(sphereScene(48, 1.5f), [](scene::Material& m) { addVolume(m, 1.0f), addDispersion(m); }); },
                          sphereView, o, aimAt(3.0), false));
    cases.back().optics = sky;
  }

  // Bounds of the image.
  for (auto [w, h] : {std::pair<uint32_t, uint32_t>{1, 1}, {7, 13}, {1, 37}, {33, 1}}) {
    Case c = image("size: " + std::to_string(w) + "x" + std::to_string(h), "size", [] { return eyeScene(1.376f); },
                   eyeView(20.0), o, 8, 0.0);
    c.width = w;
    c.height = h;
    // A 1x1 image is one pixel: one silhouette pixel would be 100% of it.
    c.overOneShare = 1.0;
    cases.push_back(c);
  }
  return cases;
}

Result run(vk::Context& context, const Case& c) {
  auto start = std::chrono::steady_clock::now();
  Result r;
  r.name = c.name;
  r.group = c.group;
  try {
    scene::Scene s = c.makeScene();
    scene::Pose firstPose = scene::evaluate(s, c.time);
    render::Renderer renderer(context, s, firstPose);
    std::vector<std::array<float, 6>> boxes;
    if (c.aimAtBoxes) {  // a camera frame builds the trees the rays are aimed at
      render::FrameSettings first{c.width, c.height, c.view(s, firstPose), glm::vec3(scene::kDefaultBackground), 1};
      render::renderFrame(renderer, firstPose, first);
      render::BvhSnapshot tree = renderer.builder()->download(*renderer.blas());
      render::BvhSnapshot::TreeBoxes t = tree.treeBoxes(0);  // the scene's first shape, the one aimed at
      boxes.insert(boxes.end(), t.internal.begin(), t.internal.end());
      boxes.insert(boxes.end(), t.leaves.begin(), t.leaves.end());
    }
    for (uint32_t frame = 0; frame < c.frames; ++frame) {
      scene::Pose pose = scene::evaluate(s, c.time);
      if (c.morph) c.morph(pose, frame);
      render::FrameSettings settings;
      settings.width = c.width;
      settings.height = c.height;
      settings.view = c.view(s, pose);
      settings.maxInterfaces = c.maxInterfaces;
      settings.optics = c.optics;
      std::vector<double> aimedDistance;
      if (c.kind == Kind::AimedRays) {
        settings.rays.resize(size_t(c.width) * c.height);
        if (c.aimAtBoxes) {
          c.aimAtBoxes(s, pose, boxes, settings.rays, aimedDistance);
        } else {
          c.aim(s, pose, settings.rays, aimedDistance);
        }
      }
      render::RenderedFrame gpu = render::renderFrame(renderer, pose, settings, true);
      ref::ReferenceSettings rs;
      rs.width = c.width;
      rs.height = c.height;
      rs.view = settings.view;
      rs.background = glm::dvec3(settings.background);
      rs.maxInterfaces = c.maxInterfaces;
      rs.rays = settings.rays;
      rs.optics = c.optics;
      ref::ReferenceImage cpu = ref::renderReference(s, pose, rs);
      for (double e : cpu.energyError) r.energyError = std::max(r.energyError, e);

      r.dropped += gpu.droppedTriangles;
      double sum = 0.0;
      int problems = 0;
      for (size_t i = 0; i < gpu.rgba.size(); ++i) {
        const glm::vec4& g = gpu.rgba[i];
        if (!std::isfinite(g.r) || !std::isfinite(g.g) || !std::isfinite(g.b) || !std::isfinite(g.a)) ++r.nanCount;
        int worst = 0;
        for (int k = 0; k < 3; ++k) {
          int e = std::abs(int(io::linearToSrgb8(g[k])) - int(io::linearToSrgb8(float(cpu.color[i][k]))));
          worst = std::max(worst, e);
          sum += e;
        }
        r.maxError = std::max(r.maxError, worst);
        r.overOne += worst > 1 ? 1 : 0;
        const gpu::TraceAov& a = gpu.aov[i];
        r.capHits += a.nodeVisits >= gpu::kTraceMaxVisits ? 1 : 0;
        if (c.kind != Kind::AimedRays) {
          if (worst > 1 && problems < 6) {
            ++problems;
            char line[256];
            std::snprintf(line, sizeof line,
                          "  pixel (%zu, %zu): %d/255 off; GPU prim %u, %u crossings; reference prim %d, %u crossings\n",
                          i % c.width, i / c.width, worst, a.primitive, a.interfaces, cpu.primitive[i], cpu.interfaces[i]);
            r.firstProblems += line;
          }
          continue;
        }
        // Slipped through: no hit, or the first hit beyond the point the ray was
        // aimed at (a ray aimed at no surface, distance -1, cannot slip).
        double slack = 1e-4 * aimedDistance[i];
        bool slipped = aimedDistance[i] >= 0.0 && (a.distance < 0.0f || double(a.distance) > aimedDistance[i] + slack);
        // Missed: the reference's first hit is not the GPU's (none, or at another distance).
        bool referenceHit = std::isfinite(cpu.distance[i]), gpuHit = a.distance >= 0.0f;
        bool missed = c.countMissedHits &&
                      (referenceHit != gpuHit ||
                       (referenceHit && std::abs(double(a.distance) - cpu.distance[i]) > 1e-4 * cpu.distance[i] + 1e-6));
        r.missedHits += missed ? 1 : 0;
        // In a closed mesh every entry has an exit: an odd count that did not
        // stop at the interface limit means the ray got out through a gap.
        bool stranded = c.closed && (a.interfaces % 2 == 1) && a.outcome != gpu::kOutcomeInterfaceLimit;
        bool selfHit = c.countSelfHits && a.interfaces > cpu.interfaces[i] &&
                       cpu.outcome[i] != gpu::kOutcomeInterfaceLimit &&
                       double(a.shortestSegment) < kSelfHitShare * cpu.shortestSegment[i];
        r.leakCount += slipped || stranded ? 1 : 0;
        r.selfHitCount += selfHit ? 1 : 0;
        if ((slipped || stranded || selfHit || missed) && problems < 6) {
          ++problems;
          char line[640];
          const scene::Ray& ray = settings.rays[i];
          std::snprintf(line, sizeof line,
                        "  ray %zu%s%s%s%s: origin (%.9g, %.9g, %.9g) direction (%.9g, %.9g, %.9g) aimed at %.9g; "
                        "GPU first hit %.9g item %u prim %u, %u crossings, outcome %u, shortest segment %.3g; reference "
                        "%.9g item %d prim %d, %u crossings, outcome %u, shortest segment %.3g\n",
                        i, slipped ? " slipped" : "", stranded ? " stranded" : "", selfHit ? " self-hit" : "",
                        missed ? " missed" : "", ray.origin.x,
                        ray.origin.y, ray.origin.z, ray.direction.x, ray.direction.y, ray.direction.z, aimedDistance[i],
                        double(a.distance), a.instance, a.primitive, a.interfaces, a.outcome,
                        double(a.shortestSegment), cpu.distance[i], cpu.instance[i], cpu.primitive[i],
                        cpu.interfaces[i], cpu.outcome[i], cpu.shortestSegment[i]);
          r.firstProblems += line;
        }
      }
      r.pixels += gpu.rgba.size();
      r.meanError += sum / 3.0;
    }
    r.meanError = r.pixels ? r.meanError / double(r.pixels) : 0.0;
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace snell::stress
