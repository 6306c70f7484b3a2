// What the golden tests share: where goldens live, how two 8-bit images are
// compared, the reference's picture of a view, and the test scenes.
#pragma once

#include "io/image_file.h"
#include "render/one_view.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/scene.h"
#include "scene/view.h"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace snell::test {

struct Tolerance {
  double withinOne = 0.999;  ///< share of pixels whose channels all differ by at most 1/255
  int maxDifference = 255;   ///< the largest channel difference allowed anywhere, in 1/255
};

/// golden/ of the checkout; SNELL_GOLDEN_DIR in the environment wins (the GPU
/// machine has the checkout elsewhere).
std::filesystem::path goldenDir();

/// The CPU double-precision reference's picture, as 8-bit sRGB.
io::Rgb8Image referenceImage(const scene::Scene& s, const scene::Pose& pose, const scene::View& view, uint32_t width,
                              uint32_t height);

struct Comparison {
  size_t pixels = 0, withinOne = 0;
  int maxDifference = 0;
  std::string firstMismatches;  ///< the first five pixels over 1/255, one per line
  io::Rgb8Image diff;          ///< mismatches in red over a dim copy of `want`
};

Comparison compare(const io::Rgb8Image& got, const io::Rgb8Image& want);

/// The viewport composite (and its whole trace) of `renderer`'s scene at
/// `pose` from `view`.
render::CompositeFrame compositeOf(render::Renderer& renderer, const scene::Pose& pose, const scene::View& view,
                                   uint32_t width, uint32_t height);

/// The procedural eye with the cornea's index of refraction set.
scene::Scene eyeWith(float ior);
/// The eye with every transmissive face taken out: what IOR 1 must look like.
scene::Scene eyeWithoutCorneaTip();
/// A right-angle glass prism showing total internal reflection, with coloured walls.
scene::Scene prismScene();
/// The eye with the aqueous humour behind the cornea (nested media).
scene::Scene eyeWithAqueous();
/// A tilted glass slab whose IOR texture steps from 1.0 (left) to 1.5 (right),
/// before a self-lit checkerboard.
scene::Scene iorStepScene();
/// Adds a mesh of one shape (flat normals per face, uv u = x / 2 + 0.5, v = y / 2 + 0.5)
/// under a root node of transform `world`; returns the shape's index.
int addFlatShape(scene::Scene& s, const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                 int material, const glm::mat4& world = glm::mat4(1.0f));
/// A closed box of glass (transmission 1, `ior`) from `lo` to `hi`, flat faces.
void addGlassBox(scene::Scene& s, glm::vec3 lo, glm::vec3 hi, float ior);
/// A model of ../shared/assets, its iridescence ignored.
scene::Scene loadModel(const std::string& relative);

}  // namespace snell::test
