#include "scene/scene_builder.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace snell::scene {

Material clearGlass(const std::string& name, float ior) {
  Material m;
  m.name = name;
  m.transmission = 1.0f;
  m.ior = ior;
  return m;
}

int addMaterial(Scene& scene, const Material& material) {
  scene.materials.push_back(material);
  return int(scene.materials.size()) - 1;
}

int addRootShape(Scene& scene, Shape shape, const glm::mat4& world) {
  if (shape.normals.empty()) {
    shape.normals.assign(shape.positions.size(), glm::vec3(0.0f));
    for (size_t t = 0; t + 2 < shape.indices.size(); t += 3) {
      const glm::vec3& a = shape.positions[shape.indices[t]];
      glm::vec3 n = glm::cross(shape.positions[shape.indices[t + 1]] - a, shape.positions[shape.indices[t + 2]] - a);
      for (int k = 0; k < 3; ++k) shape.normals[shape.indices[t + size_t(k)]] += n;
    }
    for (glm::vec3& n : shape.normals) {
      float l = glm::length(n);
      n = std::isfinite(l) && l > 0.0f ? n / l : glm::vec3(0.0f, 0.0f, 1.0f);
    }
  }
  scene.shapes.push_back(std::move(shape));
  Mesh mesh;
  mesh.name = scene.shapes.back().name;
  mesh.shapes = {int(scene.shapes.size()) - 1};
  mesh.weights.assign(scene.shapes.back().targets.size(), 0.0f);
  scene.meshes.push_back(mesh);
  Node node;
  node.name = mesh.name;
  node.mesh = int(scene.meshes.size()) - 1;
  node.matrix = world;
  scene.nodes.push_back(node);
  scene.roots.push_back(int(scene.nodes.size()) - 1);
  return int(scene.nodes.size()) - 1;
}

Shape flatShape(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices, int material) {
  Shape shape;
  shape.material = material;
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    glm::vec3 a = positions[indices[t]], b = positions[indices[t + 1]], c = positions[indices[t + 2]];
    glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    for (glm::vec3 p : {a, b, c}) {
      shape.indices.push_back(uint32_t(shape.positions.size()));
      shape.positions.push_back(p);
      shape.normals.push_back(n);
      shape.texcoords0.push_back({p.x / 2.0f + 0.5f, p.y / 2.0f + 0.5f});
    }
  }
  return shape;
}

void addQuad(Shape& shape, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
  uint32_t base = uint32_t(shape.positions.size());
  shape.positions.insert(shape.positions.end(), {a, b, c, d});
  shape.indices.insert(shape.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

void addBox(glm::vec3 lo, glm::vec3 hi, std::vector<glm::vec3>& positions, std::vector<uint32_t>& indices) {
  uint32_t base = uint32_t(positions.size());
  for (int i = 0; i < 8; ++i) positions.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
  // Corner bits: x = 1, y = 2, z = 4; each face counter-clockwise seen from outside.
  const uint32_t faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces) {
    for (uint32_t k : {f[0], f[1], f[2], f[0], f[2], f[3]}) indices.push_back(base + k);
  }
}

Shape uvSphere(uint32_t segments, float radius) {
  Shape shape;
  shape.name = "sphere";
  uint32_t rings = std::max(segments / 2, 2u);
  // Poles are single shared vertices: no gap where the fans meet.
  shape.positions.push_back({0, 0, radius});
  for (uint32_t r = 1; r < rings; ++r) {
    float theta = glm::pi<float>() * float(r) / float(rings);
    for (uint32_t k = 0; k < segments; ++k) {
      float phi = 2.0f * glm::pi<float>() * float(k) / float(segments);
      shape.positions.push_back(radius * glm::vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                                   std::cos(theta)));
    }
  }
  uint32_t south = uint32_t(shape.positions.size());
  shape.positions.push_back({0, 0, -radius});
  auto at = [&](uint32_t r, uint32_t k) { return 1 + (r - 1) * segments + k % segments; };
  for (uint32_t k = 0; k < segments; ++k) {
    shape.indices.insert(shape.indices.end(), {0, at(1, k), at(1, k + 1)});
    shape.indices.insert(shape.indices.end(), {south, at(rings - 1, k + 1), at(rings - 1, k)});
  }
  for (uint32_t r = 1; r + 1 < rings; ++r) {
    for (uint32_t k = 0; k < segments; ++k) {
      shape.indices.insert(shape.indices.end(), {at(r, k), at(r + 1, k), at(r + 1, k + 1)});
      shape.indices.insert(shape.indices.end(), {at(r, k), at(r + 1, k + 1), at(r, k + 1)});
    }
  }
  return shape;
}

std::vector<int> splitByMaterial(Scene& scene, int shape, const std::vector<int>& triangleMaterials) {
  Shape& source = scene.shapes.at(size_t(shape));
  if (triangleMaterials.size() != source.triangleCount()) {
    throw std::invalid_argument("splitByMaterial: " + std::to_string(triangleMaterials.size()) + " materials for " +
                                std::to_string(source.triangleCount()) + " triangles");
  }
  std::vector<int> order;  // materials in the order met
  std::vector<std::vector<uint32_t>> indices;
  for (size_t t = 0; t < triangleMaterials.size(); ++t) {
    const int m = triangleMaterials[t];
    size_t k = size_t(std::find(order.begin(), order.end(), m) - order.begin());
    if (k == order.size()) order.push_back(m), indices.emplace_back();
    indices[k].insert(indices[k].end(), source.indices.begin() + 3 * long(t), source.indices.begin() + 3 * long(t) + 3);
  }
  std::vector<int> parts;
  if (order.empty()) return parts;
  source.material = order[0];
  for (size_t k = 1; k < order.size(); ++k) {
    Shape part = scene.shapes[size_t(shape)];  // scene.shapes grows below: no reference held across it
    part.material = order[k];
    part.indices = std::move(indices[k]);
    part.vertexSource = shape;
    parts.push_back(int(scene.shapes.size()));
    scene.shapes.push_back(std::move(part));
  }
  scene.shapes[size_t(shape)].indices = std::move(indices[0]);
  for (Mesh& mesh : scene.meshes) {
    if (std::find(mesh.shapes.begin(), mesh.shapes.end(), shape) != mesh.shapes.end()) {
      mesh.shapes.insert(mesh.shapes.end(), parts.begin(), parts.end());
    }
  }
  return parts;
}

}  // namespace snell::scene
