// Where the picture is taken from: a glTF camera, an explicit look-at, or a
// view that frames the whole scene. Both tracers (GPU and the CPU reference)
// take their rays from the same View (see shaders/shared/trace.h).
#pragma once

#include "scene/evaluate.h"
#include "scene/scene.h"
#include "snell/defaults.h"

#include <glm/glm.hpp>

#include <optional>

namespace snell::scene {

struct LookAt {
  glm::dvec3 eye{0.0, 0.0, 1.0};
  glm::dvec3 target{0.0};
  glm::dvec3 up{0.0, 1.0, 0.0};
};

struct ViewRequest {
  int camera = -1;                ///< glTF camera index; -1: camera 0 when the scene has one
  std::optional<LookAt> lookAt;   ///< wins over any camera
  double yfov = kDefaultYfov;     ///< radians, for look-at and framed views
};

/// A ray in world space, for ray lists (FrameSettings::rays, ReferenceSettings::rays).
struct Ray {
  glm::dvec3 origin{0.0};
  glm::dvec3 direction{0.0, 0.0, -1.0};  ///< unit length
  friend bool operator==(const Ray&, const Ray&) = default;
};

/// A camera frame in world space, orthonormal, in double precision.
struct View {
  glm::dvec3 eye{0.0};
  glm::dvec3 right{1.0, 0.0, 0.0};
  glm::dvec3 up{0.0, 1.0, 0.0};
  glm::dvec3 forward{0.0, 0.0, -1.0};
  bool orthographic = false;
  /// Perspective: tan(yfov / 2). Orthographic: half the view's height.
  double halfHeight = 0.36397;
  /// The film back's offset from the optical axis in the units of halfHeight
  /// (a 2D pan that moves the picture, not the camera; halfHeight zooms).
  glm::dvec2 shift{0.0};
  std::string description;  ///< for messages: which camera this is
  friend bool operator==(const View&, const View&) = default;
};

/// Resolves the request at a pose. Throws std::invalid_argument when the
/// camera index does not exist or no node carries it, or the look-at is degenerate.
View resolveView(const Scene& scene, const Pose& pose, const ViewRequest& request);

/// A camera from a host's view matrix (world to camera) and projection, in
/// OpenGL's conventions (a camera looking down -z), for a width x height image:
/// a perspective or an orthographic projection, off-centre or not. Throws
/// std::invalid_argument saying what the matrices are not: finite, rigid, such
/// a projection, of the image's aspect (snell's pixels are square).
View viewFromMatrices(const glm::dmat4& view, const glm::dmat4& projection, uint32_t width, uint32_t height);

/// Looks down -Z at the centre of [lo, hi] from far enough that a camera of
/// vertical field `yfov` sees the box's whole bounding sphere: the view of a
/// scene without a camera. An empty box (lo.x > hi.x) frames the unit sphere
/// about the origin.
LookAt framedLookAt(const glm::dvec3& lo, const glm::dvec3& hi, double yfov);

/// World-space bounds of everything drawn at the pose (deformation included);
/// an empty scene gives min > max.
void sceneBounds(const Scene& scene, const Pose& pose, glm::dvec3& lo, glm::dvec3& hi);

/// Cheap bounds for big scenes: each shape's rest-pose box moved by its
/// item's transform (skinned items: by every joint matrix, which holds any
/// blend of them), grown by `margin` of its size for what morph targets add.
void approximateBounds(const Scene& scene, const Pose& pose, glm::dvec3& lo, glm::dvec3& hi, double margin = 0.1);

}  // namespace snell::scene
