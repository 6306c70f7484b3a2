// Camera frames from glTF cameras, look-at requests, or framing the bounds.
#include "scene/view.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace snell::scene {

namespace {

View lookAtView(const LookAt& at, double yfov, std::string description) {
  glm::dvec3 forward = at.target - at.eye;
  if (!(glm::length(forward) > 0.0) || !std::isfinite(glm::length(forward))) {
    throw std::invalid_argument("the look-at eye and target must be distinct finite points");
  }
  forward = glm::normalize(forward);
  glm::dvec3 right = glm::cross(forward, at.up);
  if (glm::length(right) < 1e-9) right = glm::cross(forward, glm::dvec3(0.0, 0.0, -1.0));  // looking along up
  right = glm::normalize(right);
  View view;
  view.eye = at.eye;
  view.forward = forward;
  view.right = right;
  view.up = glm::cross(right, forward);
  view.halfHeight = std::tan(yfov / 2.0);
  view.description = std::move(description);
  return view;
}

}  // namespace

void sceneBounds(const Scene& scene, const Pose& pose, glm::dvec3& lo, glm::dvec3& hi) {
  lo = glm::dvec3(std::numeric_limits<double>::infinity());
  hi = -lo;
  std::vector<glm::dvec3> positions, normals;
  for (const DrawItem& item : pose.items) {
    const Shape& shape = scene.shapes[size_t(item.shape)];
    glm::dmat4 world(item.world);
    if (item.deforms()) {
      deformOnCpu(item, positions, normals);
    } else {
      positions.assign(shape.positions.begin(), shape.positions.end());
    }
    for (const glm::dvec3& p : positions) {
      glm::dvec3 w = glm::dvec3(world * glm::dvec4(p, 1.0));
      if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z)) continue;
      lo = glm::min(lo, w);
      hi = glm::max(hi, w);
    }
  }
}

void approximateBounds(const Scene& scene, const Pose& pose, glm::dvec3& lo, glm::dvec3& hi, double margin) {
  lo = glm::dvec3(std::numeric_limits<double>::infinity());
  hi = -lo;
  std::vector<glm::dvec3> shapeLo(scene.shapes.size(), lo), shapeHi(scene.shapes.size(), hi);
  for (size_t s = 0; s < scene.shapes.size(); ++s) {
    for (const glm::vec3& p : scene.shapes[s].positions) {
      shapeLo[s] = glm::min(shapeLo[s], glm::dvec3(p));
      shapeHi[s] = glm::max(shapeHi[s], glm::dvec3(p));
    }
  }
  for (const DrawItem& item : pose.items) {
    glm::dvec3 a = shapeLo[size_t(item.shape)], b = shapeHi[size_t(item.shape)];
    if (!(a.x <= b.x)) continue;
    glm::dvec3 pad = margin * (b - a);
    a -= pad;
    b += pad;
    auto extend = [&](const glm::dmat4& m) {
      for (int corner = 0; corner < 8; ++corner) {
        glm::dvec3 p((corner & 1) ? b.x : a.x, (corner & 2) ? b.y : a.y, (corner & 4) ? b.z : a.z);
        glm::dvec3 w = glm::dvec3(m * glm::dvec4(p, 1.0));
        lo = glm::min(lo, w);
        hi = glm::max(hi, w);
      }
    };
    if (item.skinned && !item.jointMatrices.empty()) {
      for (const glm::dmat4& m : item.jointMatrices) extend(m);
    } else {
      extend(item.world);
    }
  }
}

View resolveView(const Scene& scene, const Pose& pose, const ViewRequest& request) {
  if (request.lookAt) return lookAtView(*request.lookAt, request.yfov, "look-at");

  int wanted = request.camera;
  if (wanted < 0 && !scene.cameras.empty()) wanted = 0;
  if (wanted >= 0) {
    if (size_t(wanted) >= scene.cameras.size()) {
      throw std::invalid_argument("camera " + std::to_string(wanted) + " does not exist; the scene has " +
                                  std::to_string(scene.cameras.size()) + " camera(s)");
    }
    for (size_t n = 0; n < scene.nodes.size() && n < pose.world.size(); ++n) {
      if (scene.nodes[n].camera != wanted) continue;
      const Camera& camera = scene.cameras[size_t(wanted)];
      glm::dmat4 m(pose.world[n]);
      View view;
      view.eye = glm::dvec3(m[3]);
      // glTF cameras look down their node's -Z with +Y up; scale is dropped.
      view.right = glm::normalize(glm::dvec3(m[0]));
      view.up = glm::normalize(glm::dvec3(m[1]));
      view.forward = -glm::normalize(glm::dvec3(m[2]));
      view.orthographic = camera.orthographic;
      view.halfHeight = camera.orthographic ? double(camera.ymag) : std::tan(double(camera.yfov) / 2.0);
      view.description = "camera " + std::to_string(wanted) + (camera.name.empty() ? "" : " '" + camera.name + "'");
      return view;
    }
    if (request.camera >= 0) {
      throw std::invalid_argument("camera " + std::to_string(wanted) + " is not placed by any node of the scene");
    }
  }

  // No camera: look down -Z at the bounds' centre from far enough to see them all.
  glm::dvec3 lo, hi;
  sceneBounds(scene, pose, lo, hi);
  glm::dvec3 centre(0.0);
  double radius = 1.0;
  if (lo.x <= hi.x) {
    centre = 0.5 * (lo + hi);
    radius = std::max(0.5 * glm::length(hi - lo), 1e-6);
  }
  double distance = radius / std::sin(request.yfov / 2.0);
  return lookAtView({centre + glm::dvec3(0.0, 0.0, distance), centre, {0.0, 1.0, 0.0}}, request.yfov,
                    "framed view of the scene");
}

}  // namespace snell::scene
