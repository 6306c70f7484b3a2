// Layout shared by shaders/comp/refine.comp, src/render/refine_pass.cpp and
// its CPU twin src/ref/refine.cpp. A subdivision surface's cage becomes the
// shape's vertices in two stages, each one dispatch for every shape whose
// cage moved this frame (a job each):
//   refine: each refined vertex, a weighted sum of cage vertices (OpenSubdiv's
//           stencil table), into a scratch buffer;
//   limit:  each vertex of the shape, its refined vertex or that vertex's
//           limit position, and its normal: the limit tangents' cross product,
//           or the refined triangles' around it where it has no tangents.
#ifndef SNELL_REFINE_H
#define SNELL_REFINE_H
#include "shared_types.h"

SNELL_GPU_BEGIN

// Binding slots of set 0. Vertex buffers are packed float triples, as the
// deform pass writes them and the BVH builder reads them.
SNELL_CONST kRefineBindingCage = 0;       // float[3 * cage vertices]: every job's cage, at its cageFirst
SNELL_CONST kRefineBindingWords = 1;      // uint[]: every job's integer tables (the job's fields say where)
SNELL_CONST kRefineBindingWeights = 2;    // float[]: every job's stencil weights
SNELL_CONST kRefineBindingRefined = 3;    // float[3 * refined vertices]: the refine stage's output
SNELL_CONST kRefineBindingPositions = 4;  // float[3 * vertexCount], out: the scene's positions
SNELL_CONST kRefineBindingNormals = 5;    // float[3 * vertexCount], out: the scene's normals
SNELL_CONST kRefineBindingJobs = 6;       // RefineJob[jobCount]

SNELL_CONST kRefineSpecWorkgroupSize = 0;
SNELL_CONST kRefineSpecStage = 1;  // kRefineStageRefine or kRefineStageLimit

SNELL_CONST kRefineStageRefine = 0;
SNELL_CONST kRefineStageLimit = 1;

// RefineJob::flags
SNELL_CONST kRefineFlagLimitSurface = 1;  // positions on the limit surface
SNELL_CONST kRefineFlagLimitNormals = 2;  // normals from the limit tangents (else the refined triangles')

// The longest stencil row a shader walks: a guard for a corrupted table,
// far past any row OpenSubdiv makes (a vertex of valence 100 at level 8).
SNELL_CONST kRefineMaxRow = 4096u;

// One shape whose cage moved. Tables in `words` are rows: row r of a table
// at T runs over entries words[T + r] .. words[T + r + 1] of its entry lists.
// 80 bytes, total: 80 bytes
struct RefineJob {
  uint refineBase;      // 4: the job's first invocation of the refine stage
  uint limitBase;       // 4: ... of the limit stage
  uint refinedCount;    // 4: refined vertices (refine stage invocations)
  uint vertexCount;     // 4: the shape's vertices (limit stage invocations)
  uint cageFirst;       // 4: its cage's first vertex in the cage buffer
  uint refinedFirst;    // 4: its first refined vertex in the refined buffer
  uint outputFirst;     // 4: its first vertex in the scene's buffers
  uint flags;           // 4: kRefineFlag*
  uint refineOffsets;   // 4: words: rows per refined vertex, then one
  uint refineIndices;   // 4: words: cage vertices of the entries
  uint refineWeights;   // 4: weights: one per entry
  uint limitOffsets;    // 4: words: rows per refined vertex, then one
  uint limitIndices;    // 4: words: refined vertices of the entries
  uint limitWeights;    // 4: weights: position, tangent, tangent per entry
  uint aroundOffsets;   // 4: words: rows per refined vertex, then one
  uint aroundTriangles; // 4: words: triangles of the entries
  uint corners;         // 4: words: three refined vertices per triangle
  uint vertexOf;        // 4: words: the refined vertex of each of the shape's vertices
  uint pad0;            // 4
  uint pad1;            // 4
};

// 16 bytes, total: 16 bytes
struct RefinePush {
  uint count;     // 4: invocations of this stage (every job's)
  uint jobCount;  // 4
  uint pad0;      // 4
  uint pad1;      // 4
};

SNELL_GPU_END
#endif
