// Orbit-rig arithmetic, in double like the rest of the view code.
#include "camera_rig.h"

#include <algorithm>
#include <cmath>

namespace snell::viewer {

namespace {
constexpr double kRadiansPerPixel = 0.008;
constexpr double kMaxPitch = 1.5533;  // 89 degrees: the up vector never flips
}  // namespace

void CameraRig::frame(const glm::dvec3& lo, const glm::dvec3& hi) {
  if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) return;  // nothing to frame
  target = 0.5 * (lo + hi);
  double radius = std::max(0.5 * glm::length(hi - lo), 1e-9);
  distance = radius / std::sin(0.5 * yfov) * 1.1;
  sceneCamera = -1;
  resetFilm();
}

void CameraRig::adopt(const scene::View& view, const glm::dvec3& pivot) {
  double along = glm::dot(pivot - view.eye, view.forward);
  distance = along > 0.0 ? along : std::max(glm::length(pivot - view.eye), 1e-9);
  target = view.eye + distance * view.forward;
  pitch = std::asin(std::clamp(-view.forward.y, -1.0, 1.0));
  yaw = std::atan2(-view.forward.x, -view.forward.z);
  if (!view.orthographic) yfov = 2.0 * std::atan(view.halfHeight);
  sceneCamera = -1;
}

void CameraRig::orbit(double dx, double dy) {
  yaw -= dx * kRadiansPerPixel;
  pitch = std::clamp(pitch + dy * kRadiansPerPixel, -kMaxPitch, kMaxPitch);
}

void CameraRig::pan(double dx, double dy, double height) {
  scene::View v = view({}, {});
  double perPixel = 2.0 * distance * std::tan(0.5 * yfov) / std::max(height, 1.0);
  target += (-dx * v.right + dy * v.up) * perPixel;
}

void CameraRig::dolly(double amount) { distance = std::max(distance * std::exp(-0.1 * amount), 1e-9); }

void CameraRig::panFilm(double dx, double dy, double height) {
  double perPixel = 2.0 / std::max(height, 1.0) / filmZoom;
  filmPan += glm::dvec2(-dx, dy) * perPixel;
}

void CameraRig::zoomFilm(double steps) { filmZoom = std::clamp(filmZoom * std::exp(0.1 * steps), 0.05, 100.0); }

void CameraRig::resetFilm() {
  filmPan = glm::dvec2(0.0);
  filmZoom = 1.0;
}

scene::View CameraRig::view(const scene::Scene& scene, const scene::Pose& pose) const {
  scene::View v;
  if (sceneCamera >= 0 && size_t(sceneCamera) < scene.cameras.size()) {
    scene::ViewRequest request;
    request.camera = sceneCamera;
    v = scene::resolveView(scene, pose, request);
  } else {
    // On a sphere around the target (yaw 0, pitch 0: on +Z), looking at it.
    glm::dvec3 forward(-std::sin(yaw) * std::cos(pitch), -std::sin(pitch), -std::cos(yaw) * std::cos(pitch));
    glm::dvec3 eye = target - distance * forward;
    glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0.0, 1.0, 0.0)));
    v.eye = eye;
    v.forward = forward;
    v.right = right;
    v.up = glm::cross(right, forward);
    v.halfHeight = std::tan(0.5 * yfov);
    v.description = "orbit camera";
  }
  // The film back: the picture moves by a fraction of the half height and is magnified.
  v.shift = filmPan * v.halfHeight;
  v.halfHeight /= filmZoom;
  return v;
}

}  // namespace snell::viewer
