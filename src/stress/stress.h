// The numerical stability grid (issue 6): hard scenes rendered by the GPU and
// by the CPU double-precision reference, compared pixel by pixel or ray by
// ray. `snell bench stress` runs the whole grid; tests/stress_test.cpp runs a
// smaller one and asserts every case's bounds.
#pragma once

#include "scene/evaluate.h"
#include "scene/optics.h"
#include "scene/scene.h"
#include "scene/subdivision.h"
#include "scene/view.h"
#include "vk/context.h"

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace snell::stress {

// ---- Scenes (stress_scenes.cpp) ----

/// `s` under a new root node that scales it by `scale`, then moves it by `offset`.
scene::Scene placed(scene::Scene s, const glm::vec3& offset, float scale);
/// The procedural eye with its cornea's IOR, in front of a coloured backdrop.
scene::Scene eyeScene(float ior);
/// The eye of eyeScene(1.376) with the aqueous humour nested in the cornea.
scene::Scene aqueousEyeScene();

/// `s` with `change` applied to every transmissive material: the optics
/// features below, for the grid's optics group and `bench methods --optics`.
scene::Scene withGlass(scene::Scene s, const std::function<void(scene::Material&)>& change);
/// KHR_materials_volume: a blue-green tint, light falling to 75% red over `distance`.
void addVolume(scene::Material& m, float distance);
/// KHR_materials_dispersion with Abbe number 20 (dense flint): three rays where it applies.
void addDispersion(scene::Material& m);
/// SNELL_materials_ior_texture: IOR + 0.05 x texture `texture`'s red channel.
void addIorTexture(scene::Material& m, int texture);

/// A closed UV sphere (shared vertices, outward winding) of radius 1 at the origin.
scene::Scene sphereScene(uint32_t segments, float ior);
/// A closed cube [-1, 1]^3, each face split into n x n quads sharing their vertices.
scene::Scene cubeScene(uint32_t n, float ior);
/// A closed slab [-1, 1]^2 x [0, thickness] in front of the backdrop.
scene::Scene slabScene(float thickness, float ior);
/// A quad of good triangles plus zero-area, duplicated and sliver triangles, before the backdrop.
scene::Scene degenerateScene();
/// A shape whose every vertex is the same point, before the backdrop.
scene::Scene collapsedScene();
/// `count` small opaque triangles in a square grid (0 and 1 included).
scene::Scene gridScene(uint64_t count);
/// A sphere with two morph targets: the first at weight 1 squashes it to 1% of
/// its depth, the second at weight 1 turns it inside out (every vertex through the centre).
scene::Scene morphingSphereScene(float ior);
/// A plano-convex lens shaped as a cornea: a spherical cap of radius `radius`
/// and height `height` over the disc it stands on in z = 0 (its base), as a
/// coarse Catmull-Clark cage of `rings` rings of `segments` quads (the rim an
/// infinitely sharp crease) fitted so that its limit surface lies on the cap
/// and the disc; refined `level` times (0: the cage itself, as a mesh).
scene::SubdivisionCage corneaCage(uint32_t rings, uint32_t segments, float radius, float height, uint32_t level);
/// corneaCage(rings, segments, 1, 0.5) of IOR 1.376 (fitted at level 2 at most), refined `level` times, in
/// front of the backdrop; without `creased` its rim is smooth (no crease: a rounded dome, convex all over,
/// for rays aimed at its edges).
scene::Scene subdividedCorneaScene(uint32_t level, bool creased = true, uint32_t rings = 3, uint32_t segments = 8);
/// A sphere whose one morph target (at weight 1) sends a band of vertices to NaN
/// and one to infinity; `poisonedTriangles` says how many triangles that spoils.
scene::Scene nonFiniteMorphScene(uint32_t& poisonedTriangles);

// ---- The grid (stress_grid.cpp) ----

enum class Kind {
  Image,      ///< camera rays; compared with the reference pixel by pixel
  AimedRays,  ///< rays aimed at exact points on a surface (ray list); leaks and self-hits counted
};

struct Case {
  std::string name;
  std::string group;  ///< far, scale, grazing, ior, watertight, edges, self-hit, degenerate, deform, optics, size
  Kind kind = Kind::Image;
  std::function<scene::Scene()> makeScene;
  uint32_t width = 64, height = 48;
  /// Where the camera is (also the camera-relative origin for ray lists).
  std::function<scene::View(const scene::Scene&, const scene::Pose&)> view;
  /// Ray lists: width * height rays and, per ray, how far its aimed point is.
  std::function<void(const scene::Scene&, const scene::Pose&, std::vector<scene::Ray>&, std::vector<double>&)> aim;
  /// Rays aimed through the trees' own boxes (the edges group): the case renders
  /// a camera frame first, which builds the trees, and this gets every child
  /// box of the first shape's bottom-level tree as the walk tests it
  /// (BvhSnapshot::storedChildBox: the exact boxes the default trees keep, in
  /// the shape's own space, which is the world for these cases' root shapes)
  /// instead of `aim`.
  std::function<void(const scene::Scene&, const scene::Pose&, const std::vector<std::array<float, 6>>& boxes,
                     std::vector<scene::Ray>&, std::vector<double>&)>
      aimAtBoxes;
  /// Whether each aimed ray's first hit must be the reference's (Result::missedHits).
  bool countMissedHits = false;
  /// Whether every aimed ray must come out again: a closed mesh of IOR 1, where
  /// every crossing is a refraction (internal reflections also count as crossings).
  bool closed = false;
  /// Whether a ray crossing more faces than the reference counts as a self-hit.
  /// Not for the glass cube: a ray entering exactly at a corner takes that
  /// corner's normal from whichever triangle it meets, and its internal
  /// reflections then diverge from the reference's without touching any origin.
  bool countSelfHits = true;
  /// Frames to render (deformation cases): weights per frame set by `morph`.
  uint32_t frames = 1;
  std::function<void(scene::Pose&, uint32_t frame)> morph;
  double time = 0.0;
  uint32_t maxInterfaces = 8;
  scene::Optics optics;  ///< Fresnel, reflections, environment: the same for GPU and reference
  /// Bounds the test asserts, stated per case: the largest channel error in
  /// 1/255 anywhere, and the share of pixels that may differ by more than 1/255.
  int maxError = 255;
  double overOneShare = 0.002;
  /// Triangles the GPU must report dropped (non-finite after deformation); -1: not checked.
  int64_t expectDropped = -1;
};

struct Result {
  std::string name, group;
  uint64_t pixels = 0;
  int maxError = 0;          ///< largest channel difference, 1/255 (sRGB 8-bit)
  double meanError = 0.0;    ///< mean channel difference, 1/255
  uint64_t overOne = 0;      ///< pixels with a channel more than 1/255 off
  uint64_t nanCount = 0;     ///< GPU pixels with a NaN or infinite channel
  uint64_t leakCount = 0;    ///< aimed rays that slipped through, or entered a closed mesh and never left
  /// Aimed rays that hit their own surface: they crossed more faces than the
  /// reference, and one of their segments after leaving a surface is far
  /// shorter than any of the reference's (a path that parts from the
  /// reference's where it passes an open edge or corner, which either
  /// precision may pass on either side, crosses another count of faces too).
  uint64_t selfHitCount = 0;
  /// Aimed rays whose first hit is not the reference's: none where the
  /// reference has one, or at another distance (Case::countMissedHits).
  uint64_t missedHits = 0;
  uint64_t capHits = 0;      ///< rays that ran into the traversal's step cap
  uint64_t dropped = 0;      ///< triangles the GPU dropped as non-finite
  double energyError = 0.0;  ///< the reference's largest |R + T - 1| at any boundary (T from amplitudes)
  std::string error;         ///< set when the case could not run (a clear error instead of a picture)
  std::string firstProblems; ///< the first few pixels or rays that leaked, self-hit or differ, GPU against reference
  double seconds = 0.0;      ///< wall time, GPU and reference together
};

struct GridOptions {
  uint32_t imageWidth = 96, imageHeight = 72;
  uint32_t aimedRaysSide = 128;  ///< aimed-ray cases trace side x side rays
  bool huge = false;             ///< include the 10^7-triangle case
};

std::vector<Case> grid(const GridOptions& options);

/// Renders one case on the GPU and with the reference and compares them.
/// Throws only for a bug in the case itself; errors of the scene or the
/// device (too large, say) come back in Result::error.
Result run(vk::Context& context, const Case& c);

}  // namespace snell::stress
