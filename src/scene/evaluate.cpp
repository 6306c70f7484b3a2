// Animation sampling (glTF 2.0 §3.11 and Appendix C: STEP, LINEAR with slerp
// for rotations, CUBICSPLINE Hermite), transform composition and the CPU
// deformation reference.
#include "scene/evaluate.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>

namespace snell::scene {

namespace {

struct LocalTransform {
  glm::vec3 translation;
  glm::quat rotation;
  glm::vec3 scale;
};

/// Samples `components` floats of a sampler at time t into `out`.
void sample(const AnimationSampler& s, double t, float* out, bool rotation) {
  const size_t n = s.times.size();
  const size_t c = size_t(s.components);
  const bool cubic = s.interpolation == Interpolation::CubicSpline;
  auto value = [&](size_t key) { return &s.values[(cubic ? key * 3 + 1 : key) * c]; };
  if (n == 0) return;
  if (t <= s.times.front() || n == 1) {
    std::copy_n(value(0), c, out);
  } else if (t >= s.times.back()) {
    std::copy_n(value(n - 1), c, out);
  } else {
    size_t k = size_t(std::upper_bound(s.times.begin(), s.times.end(), static_cast<float>(t)) - s.times.begin()) - 1;
    double t0 = s.times[k], t1 = s.times[k + 1], dt = t1 - t0;
    double u = (t - t0) / dt;
    const float* a = value(k);
    const float* b = value(k + 1);
    if (s.interpolation == Interpolation::Step) {
      std::copy_n(a, c, out);
    } else if (!cubic && rotation) {
      glm::quat qa(a[3], a[0], a[1], a[2]), qb(b[3], b[0], b[1], b[2]);
      glm::quat q = glm::slerp(glm::normalize(qa), glm::normalize(qb), static_cast<float>(u));  // shortest path
      out[0] = q.x, out[1] = q.y, out[2] = q.z, out[3] = q.w;
    } else if (!cubic) {
      for (size_t i = 0; i < c; ++i) out[i] = static_cast<float>(a[i] + (b[i] - a[i]) * u);
    } else {
      const float* outTangent = &s.values[(k * 3 + 2) * c];
      const float* inTangent = &s.values[((k + 1) * 3 + 0) * c];
      double u2 = u * u, u3 = u2 * u;
      for (size_t i = 0; i < c; ++i) {
        out[i] = static_cast<float>((2 * u3 - 3 * u2 + 1) * a[i] + (u3 - 2 * u2 + u) * dt * outTangent[i] +
                                    (-2 * u3 + 3 * u2) * b[i] + (u3 - u2) * dt * inTangent[i]);
      }
    }
  }
  if (rotation) {
    glm::quat q(out[3], out[0], out[1], out[2]);
    float length = glm::length(q);
    if (length > 0.0f) {
      q /= length;
      out[0] = q.x, out[1] = q.y, out[2] = q.z, out[3] = q.w;
    }
  }
}

glm::dmat3 cofactor(const glm::dmat3& m) {
  return glm::dmat3(glm::cross(m[1], m[2]), glm::cross(m[2], m[0]), glm::cross(m[0], m[1]));
}

}  // namespace

bool DrawItem::deforms() const {
  const Shape& s = scene->shapes[size_t(shape)];
  return skinned || s.morphed();
}

double animationDuration(const Scene& scene) {
  double duration = 0.0;
  for (const Animation& a : scene.animations) duration = std::max(duration, double(a.duration));
  return duration;
}

Pose evaluate(const Scene& scene, double time) {
  Pose pose;
  pose.time = time;
  const size_t nodeCount = scene.nodes.size();
  std::vector<LocalTransform> local(nodeCount);
  std::vector<std::vector<float>> weights(nodeCount);
  for (size_t n = 0; n < nodeCount; ++n) {
    const Node& node = scene.nodes[n];
    local[n] = {node.translation, node.rotation, node.scale};
    if (node.mesh >= 0) weights[n] = node.weights.empty() ? scene.meshes[size_t(node.mesh)].weights : node.weights;
  }
  for (const Animation& animation : scene.animations) {
    for (const AnimationChannel& channel : animation.channels) {
      const AnimationSampler& s = animation.samplers[size_t(channel.sampler)];
      LocalTransform& l = local[size_t(channel.node)];
      float value[4];
      switch (channel.path) {
        case AnimationPath::Translation:
          sample(s, time, value, false);
          l.translation = glm::vec3(value[0], value[1], value[2]);
          break;
        case AnimationPath::Scale:
          sample(s, time, value, false);
          l.scale = glm::vec3(value[0], value[1], value[2]);
          break;
        case AnimationPath::Rotation:
          sample(s, time, value, true);
          l.rotation = glm::quat(value[3], value[0], value[1], value[2]);
          break;
        case AnimationPath::Weights: {
          std::vector<float>& w = weights[size_t(channel.node)];
          w.resize(size_t(s.components));
          sample(s, time, w.data(), false);
          break;
        }
      }
    }
  }

  // Parents before children: walk down from the roots (the loader refused cycles).
  pose.world.assign(nodeCount, glm::dmat4(1.0));
  std::vector<std::pair<int, glm::dmat4>> stack;
  for (auto it = scene.roots.rbegin(); it != scene.roots.rend(); ++it) stack.push_back({*it, glm::dmat4(1.0)});
  std::vector<int> order;
  while (!stack.empty()) {
    auto [n, parent] = stack.back();
    stack.pop_back();
    const Node& node = scene.nodes[size_t(n)];
    const LocalTransform& l = local[size_t(n)];
    glm::dmat4 m = node.matrix ? glm::dmat4(*node.matrix)
                               : glm::translate(glm::dmat4(1.0), glm::dvec3(l.translation)) *
                                     glm::mat4_cast(glm::dquat(l.rotation)) * glm::scale(glm::dmat4(1.0), glm::dvec3(l.scale));
    pose.world[size_t(n)] = parent * m;
    order.push_back(n);
    for (auto child = node.children.rbegin(); child != node.children.rend(); ++child) {
      stack.push_back({*child, pose.world[size_t(n)]});
    }
  }

  for (int n : order) {
    const Node& node = scene.nodes[size_t(n)];
    if (node.mesh < 0) continue;
    std::vector<glm::dmat4> joints;
    if (node.skin >= 0) {
      const Skin& skin = scene.skins[size_t(node.skin)];
      for (size_t j = 0; j < skin.joints.size(); ++j) {
        joints.push_back(pose.world[size_t(skin.joints[j])] * glm::dmat4(skin.inverseBindMatrices[j]));
      }
    }
    std::vector<glm::mat4> copies = node.instances;
    if (copies.empty()) copies.push_back(glm::mat4(1.0f));
    for (const glm::mat4& copy : copies) {
      const glm::dmat4 instance(copy);
      for (int shapeIndex : scene.meshes[size_t(node.mesh)].shapes) {
        DrawItem item;
        item.scene = &scene;
        item.shape = shapeIndex;
        item.node = n;
        item.skinned = node.skin >= 0 && scene.shapes[size_t(shapeIndex)].skinned();
        // glTF: a skinned mesh ignores its node's transform; the joints place it.
        item.world = item.skinned ? glm::dmat4(1.0) : pose.world[size_t(n)] * instance;
        item.weights = weights[size_t(n)];
        if (item.skinned) item.jointMatrices = joints;
        pose.items.push_back(std::move(item));
      }
    }
  }
  return pose;
}

void deformOnCpu(const DrawItem& item, std::vector<glm::dvec3>& positions, std::vector<glm::dvec3>& normals) {
  const Shape& shape = item.scene->shapes[size_t(item.shape)];
  const size_t count = shape.vertexCount();
  positions.resize(count);
  normals.resize(count);
  for (size_t v = 0; v < count; ++v) {
    glm::dvec3 p = shape.positions[v];
    glm::dvec3 n = shape.normals[v];
    for (size_t t = 0; t < shape.targets.size() && t < item.weights.size(); ++t) {
      double w = item.weights[t];
      if (!shape.targets[t].positions.empty()) p += w * glm::dvec3(shape.targets[t].positions[v]);
      if (!shape.targets[t].normals.empty()) n += w * glm::dvec3(shape.targets[t].normals[v]);
    }
    if (item.skinned) {
      glm::dmat4 m(0.0);
      for (int k = 0; k < 4; ++k) m += double(shape.weights[v][k]) * item.jointMatrices[shape.joints[v][k]];
      p = glm::dvec3(m * glm::dvec4(p, 1.0));
      // The cofactor is det * inverse-transpose: right under non-uniform scale,
      // and the sign keeps a mirrored normal pointing out of the surface.
      glm::dmat3 linear(m);
      n = cofactor(linear) * n * (glm::determinant(linear) < 0.0 ? -1.0 : 1.0);
    }
    double length = glm::length(n);
    normals[v] = length > 0.0 ? n / length : n;
    positions[v] = p;
  }
}

}  // namespace snell::scene
