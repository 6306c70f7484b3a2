// Subdivision surfaces: a cage's topology refined once on the CPU by
// OpenSubdiv (Far), into the triangles the renderer draws and the stencil
// tables the refine pass applies to the cage every frame it moves
// (shaders/comp/refine.comp; its CPU twin is src/ref/refine.cpp). The shape
// that comes out holds the refined mesh at rest, so everything that reads
// shapes (trees, the reference, bounds, summaries) reads the surface the
// modeller made, not the cage.
#pragma once

#include "scene/scene.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace snell::scene {

/// USD's subdivisionScheme (UsdGeomMesh), less "none", which is a plain mesh.
enum class SubdivisionScheme { CatmullClark, Loop, Bilinear };
/// USD's interpolateBoundary.
enum class BoundaryInterpolation { None, EdgeOnly, EdgeAndCorner };
/// USD's faceVaryingLinearInterpolation, in its order.
enum class FaceVaryingInterpolation { None, CornersOnly, CornersPlus1, CornersPlus2, Boundaries, All };
/// Where a refined vertex's normal comes from: the limit surface's tangents
/// (OpenSubdiv's limit masks), or the refined triangles around it, area
/// weighted, as Blender and usdview shade a subdivided mesh.
enum class SubdivisionNormals { Limit, Mesh };

/// The most levels a cage is refined by: each multiplies a quad cage's faces by 4.
inline constexpr uint32_t kMaxSubdivisionLevel = 8;
/// Refined vertices one shape may have; a level past it is lowered, with a warning.
inline constexpr uint64_t kMaxRefinedVertices = 1ull << 22;

/// A subdivision surface's control cage with USD's UsdGeomMesh tags, at rest.
struct SubdivisionCage {
  SubdivisionScheme scheme = SubdivisionScheme::CatmullClark;
  uint32_t level = 2;  ///< uniform refinement levels, 1 to kMaxSubdivisionLevel
  /// Positions on the limit surface (Blender's "Use Limit Surface"); else the
  /// refined vertices themselves, as usdview draws a uniform refinement.
  bool limitSurface = false;
  /// The refined triangles' by default: as Blender and usdview shade, as
  /// good on the cornea lens test at level 2 (tests/refine_pass_test.cpp),
  /// and with no limit table to keep or walk.
  SubdivisionNormals normals = SubdivisionNormals::Mesh;
  std::vector<glm::vec3> positions;  ///< cage vertices, the shape's space
  std::vector<uint32_t> faceVertexCounts, faceVertexIndices;
  bool leftHanded = false;  ///< faces are clockwise seen from their front (USD orientation)
  std::vector<uint32_t> holeIndices;  ///< faces left out of the surface
  /// Creases: runs of creaseLengths[i] vertices in creaseIndices, with one
  /// sharpness per run or one per edge of every run (creaseLengths[i] - 1).
  std::vector<uint32_t> creaseIndices, creaseLengths;
  std::vector<float> creaseSharpnesses;
  std::vector<uint32_t> cornerIndices;
  std::vector<float> cornerSharpnesses;
  BoundaryInterpolation boundary = BoundaryInterpolation::EdgeAndCorner;
  FaceVaryingInterpolation faceVarying = FaceVaryingInterpolation::CornersPlus1;
  bool smoothTriangles = false;  ///< triangleSubdivisionRule "smooth" (Catmull-Clark only)
  /// Texture coordinates: one per cage vertex (uvIndices empty, refined as
  /// positions are), or face-varying, one index per face corner into uvs.
  std::vector<glm::vec2> uvs;
  std::vector<uint32_t> uvIndices;
};

/// Rows of weighted sums: row r is the sum over k in [offsets[r], offsets[r + 1])
/// of weights[k] times source value indices[k].
struct Stencils {
  std::vector<uint32_t> offsets{0};
  std::vector<uint32_t> indices;
  std::vector<float> weights;
  size_t rows() const { return offsets.size() - 1; }
};

/// What the refine pass needs to turn a moved cage into the shape's vertices:
/// built once per topology, kept while only positions change.
struct Refinement {
  SubdivisionScheme scheme = SubdivisionScheme::CatmullClark;
  uint32_t level = 0;
  bool limitSurface = false;
  SubdivisionNormals normals = SubdivisionNormals::Limit;
  uint32_t cageVertices = 0, cageFaces = 0;
  std::vector<glm::vec3> cageRest;  ///< the cage at rest: where a host's copy of it starts
  uint32_t refinedVertices = 0;  ///< the vertices of the last level
  /// Per refined vertex: its position over the cage vertices (OpenSubdiv's stencil table).
  Stencils refine;
  /// Per refined vertex, over the refined vertices: its limit position
  /// (limitSurface) and the two limit tangents whose cross product is its
  /// normal, three weights an entry (limitWeights[3k .. 3k + 2]); a row with
  /// no entries has no tangents there and takes the mesh normal.
  Stencils limit;
  std::vector<float> limitWeights;
  /// Per refined vertex, the refined triangles around it, as three refined
  /// vertices each (triangleCorners[3k .. 3k + 2]): its mesh normal.
  Stencils around;  ///< weights unused; indices are triangle numbers
  std::vector<uint32_t> triangleCorners;
  /// Per vertex of the shape: its refined vertex (a UV seam splits one into several).
  std::vector<uint32_t> vertexOf;
  /// GPU memory of the tables above.
  uint64_t bytes() const;
};

/// Refines `cage` into `shape`: its positions, normals and texcoords0 (the
/// refined vertices at rest), its triangles, and shape.refinement. A cage
/// OpenSubdiv cannot refine (a Loop cage with other faces than triangles,
/// tags out of range, a topology it refuses) is drawn as it is, and a level
/// that would pass kMaxRefinedVertices is lowered: each appends a warning
/// naming `where` to `warnings`. Throws SceneError naming `where` for a cage
/// that is not a mesh at all (counts that disagree, indices out of range,
/// faces of fewer than three vertices). `vertexBudget` is the most refined
/// vertices the shape may have. With `triangleFaces`, each of the shape's
/// triangles' cage face (a material per face splits the shape by them).
void subdivide(const SubdivisionCage& cage, Shape& shape, const std::string& where, std::vector<std::string>& warnings,
               uint64_t vertexBudget = kMaxRefinedVertices, std::vector<uint32_t>* triangleFaces = nullptr);

/// The scheme's name as USD spells it: "catmullClark", "loop", "bilinear".
const char* schemeName(SubdivisionScheme scheme);

}  // namespace snell::scene
