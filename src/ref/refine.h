// Mirrors shaders/comp/refine.comp: a subdivision cage's vertices through
// its refinement tables (scene/subdivision.h), in double, so the GPU's
// refine pass has a ground truth for any pose of the cage.
#pragma once

#include "scene/subdivision.h"

#include <glm/glm.hpp>

#include <vector>

namespace snell::ref {

/// The shape's vertices for a cage at `cage` (one position per cage
/// vertex): positions and unit normals, one per vertex of the shape.
void refineOnCpu(const scene::Refinement& refinement, const std::vector<glm::dvec3>& cage,
                 std::vector<glm::dvec3>& positions, std::vector<glm::dvec3>& normals);

}  // namespace snell::ref
