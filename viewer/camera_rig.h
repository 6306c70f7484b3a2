// The viewer's camera: an orbit rig around a target (Maya's tumble, track and
// dolly), or a glTF camera of the scene, plus the film back's 2D pan and zoom,
// which move the picture without moving the camera.
#pragma once

#include "scene/evaluate.h"
#include "scene/scene.h"
#include "scene/view.h"

#include <glm/glm.hpp>

namespace snell::viewer {

class CameraRig {
 public:
  /// -1: the orbit rig; otherwise the scene's glTF camera of that index.
  int sceneCamera = -1;
  glm::dvec3 target{0.0};
  double distance = 1.0;
  double yaw = 0.0, pitch = 0.0;  ///< radians; yaw about +Y, pitch up from the horizon
  double yfov = kDefaultYfov;     ///< the rig's vertical field of view
  glm::dvec2 filmPan{0.0};        ///< in fractions of the view's half height
  double filmZoom = 1.0;          ///< > 1 magnifies

  /// Places the rig so the box [lo, hi] fills the view from the current angles.
  void frame(const glm::dvec3& lo, const glm::dvec3& hi);
  /// Starts the rig from a view (when the user moves a glTF camera, it becomes the rig).
  void adopt(const scene::View& view, const glm::dvec3& pivot);

  /// Tumble by a mouse motion in pixels (Alt + left drag).
  void orbit(double dx, double dy);
  /// Track: moves camera and target by a mouse motion in pixels of a viewport `height` tall (Alt + middle drag).
  void pan(double dx, double dy, double height);
  /// Dolly towards the target by a mouse motion or wheel steps; never through it.
  void dolly(double amount);
  /// Film-back 2D pan by pixels of a viewport `height` tall, and zoom by wheel steps.
  void panFilm(double dx, double dy, double height);
  void zoomFilm(double steps);
  void resetFilm();

  /// The view at a pose (the glTF camera's animated place when one is chosen).
  scene::View view(const scene::Scene& scene, const scene::Pose& pose) const;
};

}  // namespace snell::viewer
