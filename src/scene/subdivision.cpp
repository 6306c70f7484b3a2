// A cage refined by OpenSubdiv's Far: topology once, then stencil tables for
// the GPU and the rest pose of the refined mesh (see subdivision.h).
#include "scene/subdivision.h"

#include <opensubdiv/far/error.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/stencilTableFactory.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <numeric>
#include <unordered_map>
#include <utility>

namespace snell::scene {

namespace osd = OpenSubdiv::Far;
namespace sdc = OpenSubdiv::Sdc;

namespace {

// Far reports problems through process-wide callbacks; each thread collects
// its own while it builds a refiner.
thread_local std::vector<std::string>* tFarMessages = nullptr;

void collectFarError(osd::ErrorType, const char* message) {
  if (tFarMessages) tFarMessages->push_back(message);
}
void collectFarWarning(const char* message) {
  if (tFarMessages) tFarMessages->push_back(message);
}

struct FarMessages {
  std::vector<std::string> messages;
  FarMessages() {
    static std::once_flag once;
    std::call_once(once, [] {
      osd::SetErrorCallback(collectFarError);
      osd::SetWarningCallback(collectFarWarning);
    });
    tFarMessages = &messages;
  }
  ~FarMessages() { tFarMessages = nullptr; }
  FarMessages(const FarMessages&) = delete;
  FarMessages& operator=(const FarMessages&) = delete;
};

// Primvar types for Far's PrimvarRefiner (its Clear / AddWithWeight interface).
template <typename V>
struct Value {
  V v{0.0};
  void Clear(void* = nullptr) { v = V(0.0); }
  void AddWithWeight(const Value& source, float weight) { v += double(weight) * source.v; }
};
using Point = Value<glm::dvec3>;
using Uv = Value<glm::dvec2>;

// A limit mask as a sparse row over the last level's vertices: the source
// "values" are the vertices themselves.
struct Unit {
  uint32_t index;
};
struct Units {
  Unit operator[](int i) const { return Unit{uint32_t(i)}; }
};
struct Mask {
  std::vector<std::pair<uint32_t, float>> terms;
  void Clear(void* = nullptr) { terms.clear(); }
  void AddWithWeight(const Unit& u, float weight) { terms.emplace_back(u.index, weight); }
};

void check(bool ok, const std::string& where, const std::string& what) {
  if (!ok) throw SceneError(where + ": " + what);
}

// Everything that makes a cage not a mesh at all: no fallback can draw it.
void checkCage(const SubdivisionCage& cage, const std::string& where) {
  const size_t vertices = cage.positions.size();
  check(vertices > 0, where, "the subdivision cage has no vertices");
  check(!cage.faceVertexCounts.empty(), where, "the subdivision cage has no faces");
  uint64_t corners = 0;
  for (size_t f = 0; f < cage.faceVertexCounts.size(); ++f) {
    check(cage.faceVertexCounts[f] >= 3, where,
          "face " + std::to_string(f) + " has " + std::to_string(cage.faceVertexCounts[f]) + " vertices (at least 3)");
    corners += cage.faceVertexCounts[f];
  }
  check(corners == cage.faceVertexIndices.size(), where,
        "faceVertexCounts add up to " + std::to_string(corners) + " corners, faceVertexIndices has " +
            std::to_string(cage.faceVertexIndices.size()));
  for (uint32_t i : cage.faceVertexIndices) {
    check(i < vertices, where,
          "face vertex index " + std::to_string(i) + " is past the cage's " + std::to_string(vertices) + " vertices");
  }
  if (cage.uvIndices.empty()) {
    check(cage.uvs.empty() || cage.uvs.size() == vertices, where,
          std::to_string(cage.uvs.size()) + " texture coordinates for " + std::to_string(vertices) +
              " vertices (give one a vertex, or face-varying indices)");
  } else {
    check(cage.uvIndices.size() == corners, where,
          std::to_string(cage.uvIndices.size()) + " face-varying texture indices for " + std::to_string(corners) +
              " face corners");
    for (uint32_t i : cage.uvIndices) {
      check(i < cage.uvs.size(), where,
            "texture coordinate index " + std::to_string(i) + " is past the " + std::to_string(cage.uvs.size()) +
                " texture coordinates");
    }
  }
  for (const glm::vec3& p : cage.positions) check(std::isfinite(p.x + p.y + p.z), where, "a cage vertex is not finite");
}

// Why OpenSubdiv should not be asked to refine this cage (its tags out of
// range, a scheme the faces do not suit), or "" when it may.
std::string tagProblem(const SubdivisionCage& cage) {
  const size_t vertices = cage.positions.size(), faces = cage.faceVertexCounts.size();
  if (cage.scheme == SubdivisionScheme::Loop) {
    for (uint32_t n : cage.faceVertexCounts) {
      if (n != 3) return "the Loop scheme refines triangles only, and the cage has a face of " + std::to_string(n);
    }
  }
  for (uint32_t h : cage.holeIndices) {
    if (h >= faces) return "hole index " + std::to_string(h) + " is past the cage's " + std::to_string(faces) + " faces";
  }
  uint64_t runs = 0, edges = 0;
  for (uint32_t n : cage.creaseLengths) {
    if (n < 2) return "a crease of " + std::to_string(n) + " vertex (at least 2)";
    runs += n;
    edges += n - 1;
  }
  if (runs != cage.creaseIndices.size()) {
    return "creaseLengths add up to " + std::to_string(runs) + " vertices, creaseIndices has " +
           std::to_string(cage.creaseIndices.size());
  }
  if (cage.creaseSharpnesses.size() != cage.creaseLengths.size() && cage.creaseSharpnesses.size() != edges) {
    return std::to_string(cage.creaseSharpnesses.size()) + " crease sharpnesses for " +
           std::to_string(cage.creaseLengths.size()) + " creases of " + std::to_string(edges) + " edges";
  }
  for (uint32_t i : cage.creaseIndices) {
    if (i >= vertices) return "crease vertex " + std::to_string(i) + " is past the cage's " + std::to_string(vertices) + " vertices";
  }
  if (cage.cornerSharpnesses.size() != cage.cornerIndices.size()) {
    return std::to_string(cage.cornerSharpnesses.size()) + " corner sharpnesses for " +
           std::to_string(cage.cornerIndices.size()) + " corners";
  }
  for (uint32_t i : cage.cornerIndices) {
    if (i >= vertices) return "corner vertex " + std::to_string(i) + " is past the cage's " + std::to_string(vertices) + " vertices";
  }
  for (float s : cage.creaseSharpnesses) {
    if (!std::isfinite(s)) return "a crease sharpness is not finite";
  }
  for (float s : cage.cornerSharpnesses) {
    if (!std::isfinite(s)) return "a corner sharpness is not finite";
  }
  return "";
}

// The vertices a level of refinement would have, about: a Catmull-Clark
// cage's first level turns an n-gon into n quads, later levels 4 faces each.
uint64_t estimatedVertices(const SubdivisionCage& cage, uint32_t level) {
  uint64_t faces = 0;
  for (uint32_t n : cage.faceVertexCounts) faces += cage.scheme == SubdivisionScheme::Loop ? 1 : n;
  if (level == 0) return cage.positions.size();
  faces *= cage.scheme == SubdivisionScheme::Loop ? 4 : 1;
  for (uint32_t l = 1; l < level; ++l) faces *= 4;
  return faces;
}

sdc::SchemeType schemeType(SubdivisionScheme s) {
  switch (s) {
    case SubdivisionScheme::Loop: return sdc::SCHEME_LOOP;
    case SubdivisionScheme::Bilinear: return sdc::SCHEME_BILINEAR;
    default: return sdc::SCHEME_CATMARK;
  }
}

sdc::Options schemeOptions(const SubdivisionCage& cage) {
  sdc::Options options;
  options.SetVtxBoundaryInterpolation(cage.boundary == BoundaryInterpolation::None       ? sdc::Options::VTX_BOUNDARY_NONE
                                      : cage.boundary == BoundaryInterpolation::EdgeOnly ? sdc::Options::VTX_BOUNDARY_EDGE_ONLY
                                                                                        : sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
  static const sdc::Options::FVarLinearInterpolation kFVar[] = {
      sdc::Options::FVAR_LINEAR_NONE,          sdc::Options::FVAR_LINEAR_CORNERS_ONLY, sdc::Options::FVAR_LINEAR_CORNERS_PLUS1,
      sdc::Options::FVAR_LINEAR_CORNERS_PLUS2, sdc::Options::FVAR_LINEAR_BOUNDARIES,   sdc::Options::FVAR_LINEAR_ALL};
  options.SetFVarLinearInterpolation(kFVar[int(cage.faceVarying)]);
  options.SetTriangleSubdivision(cage.smoothTriangles ? sdc::Options::TRI_SUB_SMOOTH : sdc::Options::TRI_SUB_CATMARK);
  options.SetCreasingMethod(sdc::Options::CREASE_UNIFORM);
  return options;
}

// The cage's topology for Far; the arrays it points into live here.
struct Descriptor {
  std::vector<int> counts, indices, creasePairs, corners, holes, uvIndices;
  std::vector<float> creaseWeights, cornerWeights;
  osd::TopologyDescriptor::FVarChannel channel;
  osd::TopologyDescriptor desc;

  explicit Descriptor(const SubdivisionCage& cage) {
    counts.assign(cage.faceVertexCounts.begin(), cage.faceVertexCounts.end());
    indices.assign(cage.faceVertexIndices.begin(), cage.faceVertexIndices.end());
    size_t at = 0, edge = 0;
    const bool perEdge = cage.creaseSharpnesses.size() != cage.creaseLengths.size();
    for (size_t c = 0; c < cage.creaseLengths.size(); ++c) {
      for (uint32_t k = 0; k + 1 < cage.creaseLengths[c]; ++k, ++edge) {
        creasePairs.push_back(int(cage.creaseIndices[at + k]));
        creasePairs.push_back(int(cage.creaseIndices[at + k + 1]));
        creaseWeights.push_back(perEdge ? cage.creaseSharpnesses[edge] : cage.creaseSharpnesses[c]);
      }
      at += cage.creaseLengths[c];
    }
    corners.assign(cage.cornerIndices.begin(), cage.cornerIndices.end());
    cornerWeights = cage.cornerSharpnesses;
    holes.assign(cage.holeIndices.begin(), cage.holeIndices.end());
    desc.numVertices = int(cage.positions.size());
    desc.numFaces = int(counts.size());
    desc.numVertsPerFace = counts.data();
    desc.vertIndicesPerFace = indices.data();
    desc.numCreases = int(creaseWeights.size());
    desc.creaseVertexIndexPairs = creasePairs.data();
    desc.creaseWeights = creaseWeights.data();
    desc.numCorners = int(corners.size());
    desc.cornerVertexIndices = corners.data();
    desc.cornerWeights = cornerWeights.data();
    desc.numHoles = int(holes.size());
    desc.holeIndices = holes.data();
    if (!cage.uvIndices.empty()) {
      uvIndices.assign(cage.uvIndices.begin(), cage.uvIndices.end());
      channel.numValues = int(cage.uvs.size());
      channel.valueIndices = uvIndices.data();
      desc.numFVarChannels = 1;
      desc.fvarChannels = &channel;
    }
  }
};

// Refines level by level with Far's own primvar refiner: the rest pose the
// GPU's stencils must reproduce.
template <typename T>
std::vector<T> refineLevels(const osd::PrimvarRefiner& refiner, const osd::TopologyRefiner& topology,
                            std::vector<T> values, bool faceVarying) {
  for (int level = 1; level <= topology.GetMaxLevel(); ++level) {
    const osd::TopologyLevel& l = topology.GetLevel(level);
    std::vector<T> next(size_t(faceVarying ? l.GetNumFVarValues(0) : l.GetNumVertices()));
    T* from = values.data();  // Far takes the destination by reference
    T* to = next.data();
    if (faceVarying) {
      refiner.InterpolateFaceVarying(level, from, to, 0);
    } else {
      refiner.Interpolate(level, from, to);
    }
    values = std::move(next);
  }
  return values;
}

// The triangles of a level and the shape's vertices: one per (vertex,
// texture coordinate value) pair met at a face corner.
struct Triangles {
  std::vector<uint32_t> indices;   ///< the shape's, 3 a triangle
  /// Every face's triangles in the level's vertices, holes too: a hole (a
  /// face another material's mesh draws, in USD) still shapes its
  /// neighbours' normals, as it shapes their limit surface.
  std::vector<uint32_t> corners;
  std::vector<uint32_t> vertexOf;  ///< per shape vertex: its vertex of the level
  std::vector<int> uvOf;           ///< per shape vertex: its face-varying value (or -1)
  std::vector<uint32_t> faces;     ///< per triangle of `indices`: the level's face it is part of
};

// Fans of `faces` faces, each read by face(f, vertices, uvs), which says
// whether the face is a hole; turned round where the cage is left-handed.
template <typename Face>
Triangles triangulate(int faces, size_t vertices, bool faceVarying, bool flip, Face&& face) {
  Triangles out;
  std::unordered_map<uint64_t, uint32_t> made;
  auto vertexFor = [&](uint32_t v, int uv) {
    auto [it, inserted] = made.emplace((uint64_t(v) << 32) | uint32_t(uv), uint32_t(out.vertexOf.size()));
    if (inserted) {
      out.vertexOf.push_back(v);
      out.uvOf.push_back(uv);
    }
    return it->second;
  };
  if (!faceVarying) {
    out.vertexOf.resize(vertices);
    std::iota(out.vertexOf.begin(), out.vertexOf.end(), 0u);
    out.uvOf.assign(vertices, -1);
  }
  std::vector<uint32_t> verts, shapeVerts;
  std::vector<int> uvs;
  for (int f = 0; f < faces; ++f) {
    verts.clear(), uvs.clear(), shapeVerts.clear();
    const bool hole = face(f, verts, uvs);
    for (size_t k = 1; k + 1 < verts.size(); ++k) {
      size_t b = flip ? k + 1 : k, c = flip ? k : k + 1;
      out.corners.insert(out.corners.end(), {verts[0], verts[b], verts[c]});
    }
    if (hole) continue;
    for (size_t k = 0; k < verts.size(); ++k) shapeVerts.push_back(faceVarying ? vertexFor(verts[k], uvs[k]) : verts[k]);
    for (size_t k = 1; k + 1 < verts.size(); ++k) {
      size_t b = flip ? k + 1 : k, c = flip ? k : k + 1;
      out.indices.insert(out.indices.end(), {shapeVerts[0], shapeVerts[b], shapeVerts[c]});
      out.faces.push_back(uint32_t(f));
    }
  }
  return out;
}

// Area-weighted normals of triangles over `points`, per point.
std::vector<glm::dvec3> meshNormals(const std::vector<uint32_t>& corners, const std::vector<glm::dvec3>& points) {
  std::vector<glm::dvec3> sum(points.size(), glm::dvec3(0.0));
  for (size_t t = 0; t + 2 < corners.size(); t += 3) {
    const glm::dvec3 &a = points[corners[t]], &b = points[corners[t + 1]], &c = points[corners[t + 2]];
    glm::dvec3 n = glm::cross(b - a, c - a);
    for (int k = 0; k < 3; ++k) sum[corners[t + size_t(k)]] += n;
  }
  return sum;
}

glm::vec3 unit(const glm::dvec3& n) {
  double l = glm::length(n);
  return l > 0.0 && std::isfinite(l) ? glm::vec3(n / l) : glm::vec3(0.0f, 0.0f, 1.0f);
}

// Per refined vertex, the triangles around it (their numbers), as rows.
Stencils trianglesAround(const std::vector<uint32_t>& corners, size_t vertices) {
  Stencils around;
  around.offsets.assign(vertices + 1, 0);
  for (uint32_t c : corners) ++around.offsets[c + 1];
  std::partial_sum(around.offsets.begin(), around.offsets.end(), around.offsets.begin());
  around.indices.resize(corners.size());
  std::vector<uint32_t> next(around.offsets.begin(), around.offsets.end() - 1);
  for (size_t k = 0; k < corners.size(); ++k) around.indices[next[corners[k]]++] = uint32_t(k / 3);
  return around;
}

// Sums the weights a mask gives each index, in index order.
std::vector<std::pair<uint32_t, float>> merged(std::vector<std::pair<uint32_t, float>> terms) {
  std::sort(terms.begin(), terms.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::pair<uint32_t, float>> out;
  for (const auto& t : terms) {
    if (!out.empty() && out.back().first == t.first) {
      out.back().second += t.second;
    } else {
      out.push_back(t);
    }
  }
  return out;
}

// The limit masks of every last-level vertex, as one row of (position,
// tangent, tangent) weights over the last level's vertices. A tangent pair
// is turned round where its cross product points against the refined mesh's
// normal at rest, and dropped where it has none, so the GPU's normal is the
// mesh's there.
void limitStencils(const osd::PrimvarRefiner& refiner, const std::vector<glm::dvec3>& rest,
                   const std::vector<glm::dvec3>& restMeshNormals, Refinement& out) {
  const size_t n = rest.size();
  std::vector<Mask> position(n), tangent1(n), tangent2(n);
  refiner.Limit(Units{}, position, tangent1, tangent2);
  out.limit = Stencils{};
  out.limitWeights.clear();
  for (size_t v = 0; v < n; ++v) {
    auto p = merged(position[v].terms), t1 = merged(tangent1[v].terms), t2 = merged(tangent2[v].terms);
    glm::dvec3 d1(0.0), d2(0.0);
    for (const auto& [i, w] : t1) d1 += double(w) * rest[i];
    for (const auto& [i, w] : t2) d2 += double(w) * rest[i];
    glm::dvec3 normal = glm::cross(d1, d2);
    const double scale = glm::dot(restMeshNormals[v], restMeshNormals[v]);
    bool usable = glm::dot(normal, normal) > 1e-20 * std::max(scale, 1e-300);
    double sign = glm::dot(normal, restMeshNormals[v]) < 0.0 ? -1.0 : 1.0;
    // One entry per index any of the three masks names.
    std::vector<uint32_t> names;
    for (const auto* mask : {&p, &t1, &t2}) {
      for (const auto& t : *mask) names.push_back(t.first);
    }
    std::sort(names.begin(), names.end());
    names.erase(std::unique(names.begin(), names.end()), names.end());
    auto weightOf = [](const std::vector<std::pair<uint32_t, float>>& mask, uint32_t index) {
      auto it = std::lower_bound(mask.begin(), mask.end(), index, [](const auto& t, uint32_t i) { return t.first < i; });
      return it != mask.end() && it->first == index ? it->second : 0.0f;
    };
    for (uint32_t index : names) {
      out.limit.indices.push_back(index);
      out.limitWeights.push_back(weightOf(p, index));
      out.limitWeights.push_back(usable ? float(sign) * weightOf(t1, index) : 0.0f);
      out.limitWeights.push_back(usable ? weightOf(t2, index) : 0.0f);
    }
    out.limit.offsets.push_back(uint32_t(out.limit.indices.size()));
  }
  out.limit.weights.clear();
}

// What subdivide() draws at `level`; level 0 is the cage itself, whose
// "stencils" copy each cage vertex.
void refineAt(const SubdivisionCage& cage, uint32_t level, const osd::TopologyRefiner* topology, Shape& shape,
              std::vector<uint32_t>* triangleFaces) {
  auto refinement = std::make_shared<Refinement>();
  Refinement& r = *refinement;
  r.scheme = cage.scheme;
  r.level = level;
  r.limitSurface = level > 0 && cage.limitSurface;
  r.normals = level > 0 && cage.scheme != SubdivisionScheme::Bilinear ? cage.normals : SubdivisionNormals::Mesh;
  r.cageVertices = uint32_t(cage.positions.size());
  r.cageFaces = uint32_t(cage.faceVertexCounts.size());
  r.cageRest = cage.positions;
  const bool faceVarying = !cage.uvIndices.empty();
  const bool vertexUvs = !faceVarying && !cage.uvs.empty();

  std::vector<glm::dvec3> rest;
  std::vector<glm::dvec2> uvValues;  // per refined vertex, or per face-varying value
  Triangles triangles;
  if (level == 0) {
    // The cage as a level of its own, walked as a refined level is.
    rest.assign(cage.positions.begin(), cage.positions.end());
    std::vector<size_t> firstCorner(cage.faceVertexCounts.size() + 1, 0);
    for (size_t f = 0; f < cage.faceVertexCounts.size(); ++f) firstCorner[f + 1] = firstCorner[f] + cage.faceVertexCounts[f];
    std::vector<char> hole(cage.faceVertexCounts.size(), 0);
    for (uint32_t h : cage.holeIndices) {
      if (h < hole.size()) hole[h] = 1;
    }
    triangles = triangulate(int(cage.faceVertexCounts.size()), rest.size(), faceVarying, cage.leftHanded,
                            [&](int f, std::vector<uint32_t>& verts, std::vector<int>& uvs) {
                              for (size_t k = firstCorner[size_t(f)]; k < firstCorner[size_t(f) + 1]; ++k) {
                                verts.push_back(cage.faceVertexIndices[k]);
                                uvs.push_back(faceVarying ? int(cage.uvIndices[k]) : -1);
                              }
                              return hole[size_t(f)] != 0;
                            });
    uvValues.assign(cage.uvs.begin(), cage.uvs.end());
    r.refine.offsets.resize(rest.size() + 1);
    std::iota(r.refine.offsets.begin(), r.refine.offsets.end(), 0u);
    r.refine.indices.resize(rest.size());
    std::iota(r.refine.indices.begin(), r.refine.indices.end(), 0u);
    r.refine.weights.assign(rest.size(), 1.0f);
  } else {
    const osd::PrimvarRefiner primvars(*topology);
    std::vector<Point> points(cage.positions.size());
    for (size_t v = 0; v < points.size(); ++v) points[v].v = glm::dvec3(cage.positions[v]);
    std::vector<Point> refined = refineLevels(primvars, *topology, std::move(points), false);
    for (const Point& p : refined) rest.push_back(p.v);
    if (faceVarying || vertexUvs) {
      std::vector<Uv> uvs(cage.uvs.size());
      for (size_t i = 0; i < uvs.size(); ++i) uvs[i].v = glm::dvec2(cage.uvs[i]);
      std::vector<Uv> refinedUvs = refineLevels(primvars, *topology, std::move(uvs), faceVarying);
      if (r.limitSurface) {
        std::vector<Uv> limitUvs(refinedUvs.size());
        if (faceVarying) {
          primvars.LimitFaceVarying(refinedUvs, limitUvs, 0);
        } else {
          primvars.Limit(refinedUvs, limitUvs);
        }
        refinedUvs = std::move(limitUvs);
      }
      for (const Uv& uv : refinedUvs) uvValues.push_back(uv.v);
    }
    const osd::TopologyLevel& last = topology->GetLevel(int(level));
    triangles = triangulate(last.GetNumFaces(), rest.size(), faceVarying, cage.leftHanded,
                            [&](int f, std::vector<uint32_t>& verts, std::vector<int>& uvs) {
                              auto fv = last.GetFaceVertices(f);
                              for (int k = 0; k < fv.size(); ++k) {
                                verts.push_back(uint32_t(fv[k]));
                                uvs.push_back(faceVarying ? last.GetFaceFVarValues(f, 0)[k] : -1);
                              }
                              return last.IsFaceHole(f);
                            });

    osd::StencilTableFactory::Options options;
    options.generateOffsets = true;
    options.generateIntermediateLevels = false;
    options.generateControlVerts = false;
    options.interpolationMode = osd::StencilTableFactory::INTERPOLATE_VERTEX;
    std::unique_ptr<const osd::StencilTable> table(osd::StencilTableFactory::Create(*topology, options));
    r.refine.offsets.assign(1, 0);
    for (int s = 0; s < table->GetNumStencils(); ++s) {
      r.refine.offsets.push_back(uint32_t(table->GetOffsets()[size_t(s)] + table->GetSizes()[size_t(s)]));
    }
    r.refine.indices.assign(table->GetControlIndices().begin(), table->GetControlIndices().end());
    r.refine.weights.assign(table->GetWeights().begin(), table->GetWeights().end());
  }
  r.refinedVertices = uint32_t(rest.size());
  r.vertexOf = triangles.vertexOf;
  r.around = trianglesAround(triangles.corners, rest.size());
  r.triangleCorners = triangles.corners;

  // The rest pose, as the GPU's refine pass would draw it.
  std::vector<glm::dvec3> restMesh = meshNormals(triangles.corners, rest);
  std::vector<glm::dvec3> positions = rest, normals = restMesh;
  if (level > 0 && (r.limitSurface || r.normals == SubdivisionNormals::Limit)) {
    const osd::PrimvarRefiner primvars(*topology);
    limitStencils(primvars, rest, restMesh, r);
    std::vector<Point> last(rest.size()), limit(rest.size()), t1(rest.size()), t2(rest.size());
    for (size_t v = 0; v < rest.size(); ++v) last[v].v = rest[v];
    primvars.Limit(last, limit, t1, t2);
    for (size_t v = 0; v < rest.size(); ++v) {
      if (r.limitSurface) positions[v] = limit[v].v;
      if (r.normals != SubdivisionNormals::Limit) continue;
      glm::dvec3 n = glm::cross(t1[v].v, t2[v].v);
      // The stencils' own verdict on each vertex: turned round, or no tangents.
      const uint32_t first = r.limit.offsets[v], end = r.limit.offsets[v + 1];
      bool hasTangents = false;
      for (uint32_t k = first; k < end; ++k) hasTangents = hasTangents || r.limitWeights[3 * k + 2] != 0.0f;
      if (hasTangents) normals[v] = glm::dot(n, restMesh[v]) < 0.0 ? -n : n;
    }
  }

  shape.positions.clear(), shape.normals.clear(), shape.texcoords0.clear();
  for (size_t i = 0; i < triangles.vertexOf.size(); ++i) {
    const uint32_t v = triangles.vertexOf[i];
    shape.positions.push_back(glm::vec3(positions[v]));
    shape.normals.push_back(unit(normals[v]));
    if (faceVarying) shape.texcoords0.push_back(glm::vec2(uvValues[size_t(triangles.uvOf[i])]));
    if (vertexUvs) shape.texcoords0.push_back(glm::vec2(uvValues[v]));
  }
  shape.indices = std::move(triangles.indices);
  if (triangleFaces) {  // each refined face's cage face, down the levels
    *triangleFaces = std::move(triangles.faces);
    for (uint32_t& f : *triangleFaces) {
      for (uint32_t l = level; l > 0; --l) f = uint32_t(topology->GetLevel(int(l)).GetFaceParentFace(int(f)));
    }
  }
  shape.cageVertices = r.cageVertices;
  shape.refinedVertexCount = uint32_t(r.vertexOf.size());
  shape.refinement = std::move(refinement);
}

}  // namespace

uint64_t Refinement::bytes() const {
  auto words = [](const Stencils& s) { return (s.offsets.size() + s.indices.size() + s.weights.size()) * 4; };
  return words(refine) + words(limit) + words(around) + (limitWeights.size() + triangleCorners.size() + vertexOf.size()) * 4;
}

const char* schemeName(SubdivisionScheme scheme) {
  switch (scheme) {
    case SubdivisionScheme::Loop: return "loop";
    case SubdivisionScheme::Bilinear: return "bilinear";
    default: return "catmullClark";
  }
}

void subdivide(const SubdivisionCage& cage, Shape& shape, const std::string& where, std::vector<std::string>& warnings,
               uint64_t vertexBudget, std::vector<uint32_t>* triangleFaces) {
  checkCage(cage, where);
  uint32_t level = cage.level;
  if (level > kMaxSubdivisionLevel) {
    warnings.push_back(where + ": subdivision level " + std::to_string(level) + " is lowered to " +
                       std::to_string(kMaxSubdivisionLevel) + ", the most snell refines");
    level = kMaxSubdivisionLevel;
  }
  const uint32_t asked = level;
  while (level > 0 && estimatedVertices(cage, level) > vertexBudget) --level;
  if (level != asked) {
    warnings.push_back(where + ": subdivision level " + std::to_string(asked) + " would make about " +
                       std::to_string(estimatedVertices(cage, asked)) + " vertices, past the " +
                       std::to_string(vertexBudget) + " snell refines a mesh to; level " + std::to_string(level) +
                       (level ? " is drawn" : " (the cage) is drawn"));
  }
  if (level == 0) return refineAt(cage, 0, nullptr, shape, triangleFaces);
  std::string problem = tagProblem(cage);
  if (!problem.empty()) {
    warnings.push_back(where + ": " + problem + "; the cage is drawn unrefined");
    return refineAt(cage, 0, nullptr, shape, triangleFaces);
  }
  Descriptor descriptor(cage);
  FarMessages messages;
  using Factory = osd::TopologyRefinerFactory<osd::TopologyDescriptor>;
  std::unique_ptr<osd::TopologyRefiner> topology(
      Factory::Create(descriptor.desc, Factory::Options(schemeType(cage.scheme), schemeOptions(cage))));
  if (!topology) {
    std::string why = messages.messages.empty() ? std::string("OpenSubdiv refused its topology") : messages.messages.front();
    warnings.push_back(where + ": " + why + "; the cage is drawn unrefined");
    return refineAt(cage, 0, nullptr, shape, triangleFaces);
  }
  osd::TopologyRefiner::UniformOptions uniform{int(level)};
  uniform.fullTopologyInLastLevel = true;
  topology->RefineUniform(uniform);
  for (const std::string& m : messages.messages) warnings.push_back(where + ": OpenSubdiv: " + m);
  refineAt(cage, level, topology.get(), shape, triangleFaces);
}

}  // namespace snell::scene
