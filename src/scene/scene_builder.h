// Scenes built in code, a shape at a time: the stability grid's scenes and the
// tests' (golden images, optics, the reference tracer) use these, so a shape
// is made one way wherever it is made.
#pragma once

#include "scene/scene.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace snell::scene {

/// Clear glass called `name`: transmission 1 at `ior`, glTF's defaults otherwise.
Material clearGlass(const std::string& name, float ior);
/// Appends `material`; returns its index.
int addMaterial(Scene& scene, const Material& material);
/// Appends `shape` in a mesh of its own under a root node placed by `world`;
/// returns the node's index. Smooth vertex normals are computed when the
/// shape has none (a face with no area contributes nothing).
int addRootShape(Scene& scene, Shape shape, const glm::mat4& world = glm::mat4(1.0f));
/// The triangles `indices` of `positions` with no vertex shared between faces,
/// so each face has its own flat normal; texture coordinates (x / 2 + 0.5,
/// y / 2 + 0.5) map [-1, 1] in x and y onto a texture.
Shape flatShape(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices, int material);
/// Appends the quad a, b, c, d (counter-clockwise seen from its front) as two triangles.
void addQuad(Shape& shape, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d);
/// Appends the box [lo, hi]'s 12 triangles, counter-clockwise seen from outside.
void addBox(glm::vec3 lo, glm::vec3 hi, std::vector<glm::vec3>& positions, std::vector<uint32_t>& indices);
/// Splits shape `shape` by its triangles' materials (one per triangle of its
/// indices, -1 the default): it keeps the triangles of the first material met,
/// and each other material's go to a part (Shape::vertexSource) appended to
/// the scene's shapes and to every mesh that holds the shape. Returns the parts.
std::vector<int> splitByMaterial(Scene& scene, int shape, const std::vector<int>& triangleMaterials);
/// A UV sphere about the origin: `segments` around, half as many rings, one vertex at each pole.
Shape uvSphere(uint32_t segments, float radius);

}  // namespace snell::scene
