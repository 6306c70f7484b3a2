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
  return lookAtView(framedLookAt(lo, hi, request.yfov), request.yfov, "framed view of the scene");
}

LookAt framedLookAt(const glm::dvec3& lo, const glm::dvec3& hi, double yfov) {
  glm::dvec3 centre(0.0);
  double radius = 1.0;
  if (lo.x <= hi.x) {
    centre = 0.5 * (lo + hi);
    radius = std::max(0.5 * glm::length(hi - lo), 1e-6);
  }
  const double distance = radius / std::sin(yfov / 2.0);
  return {centre + glm::dvec3(0.0, 0.0, distance), centre, {0.0, 1.0, 0.0}};
}

// A camera frame from a host's view and projection matrices (OpenGL's
// conventions). The trace's ray through a pixel (shared/trace.h) has slopes
// sx = ndc.x * halfHeight * aspect + shift.x, sy = ndc.y * halfHeight + shift.y;
// an off-centre projection is exactly such a window of slopes (perspective)
// or of offsets (orthographic).
View viewFromMatrices(const glm::dmat4& view, const glm::dmat4& projection, uint32_t width, uint32_t height) {
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      if (!std::isfinite(view[c][r]) || !std::isfinite(projection[c][r])) {
        throw std::invalid_argument("view: the camera matrices are not finite");
      }
    }
  }
  glm::dmat4 toWorld = glm::inverse(view);
  const glm::dmat4& p = projection;  // p[column][row]
  View v;
  v.description = "the host's camera matrices";
  v.right = glm::dvec3(toWorld[0]);
  v.up = glm::dvec3(toWorld[1]);
  v.forward = -glm::dvec3(toWorld[2]);
  v.eye = glm::dvec3(toWorld[3]);
  double lr = glm::length(v.right), lu = glm::length(v.up), lf = glm::length(v.forward);
  if (!(lr > 0.0 && lu > 0.0 && lf > 0.0) || !std::isfinite(lr * lu * lf)) {
    throw std::invalid_argument("view: the view matrix is singular");
  }
  v.right /= lr, v.up /= lu, v.forward /= lf;
  if (std::abs(glm::dot(v.right, v.up)) > 1e-4 || std::abs(glm::dot(v.right, v.forward)) > 1e-4 ||
      std::abs(glm::dot(v.up, v.forward)) > 1e-4) {
    throw std::invalid_argument("view: the view matrix shears (its axes are not at right angles)");
  }
  if (p[0][3] != 0.0 || p[1][3] != 0.0 || p[0][1] != 0.0 || p[1][0] != 0.0) {
    throw std::invalid_argument(
        "view: the projection is not a perspective or orthographic one (it mixes x and y, or x and y into w)");
  }
  bool perspective = p[2][3] < 0.0 && p[3][3] == 0.0;
  v.orthographic = p[2][3] == 0.0 && p[3][3] != 0.0;
  if (!perspective && !v.orthographic) {
    throw std::invalid_argument("view: the projection is neither perspective (w = -z) nor orthographic (w = 1)");
  }
  if (!(p[0][0] > 0.0 && p[1][1] > 0.0)) throw std::invalid_argument("view: the projection flips or collapses x or y");
  double w = perspective ? -p[2][3] : p[3][3];  // clip w per unit of -z, or the constant w
  double sx = p[0][0] / w, sy = p[1][1] / w;
  double aspect = double(width) / double(height);
  if (std::abs(sy / sx / aspect - 1.0) > 1e-3) {
    throw std::invalid_argument("view: the projection's aspect " + std::to_string(sy / sx) + " is not the view's " +
                std::to_string(width) + "x" + std::to_string(height) + " (" + std::to_string(aspect) +
                "): snell's pixels are square");
  }
  v.halfHeight = 1.0 / sy;
  if (perspective) {
    v.shift = glm::dvec2(p[2][0] / p[0][0], p[2][1] / p[1][1]);
  } else {
    v.shift = glm::dvec2(-p[3][0] / p[0][0], -p[3][1] / p[1][1]);
  }
  return v;
}

}  // namespace snell::scene
