// The GPU deform pass against the CPU double-precision evaluation, on every
// skinned or morphed sample model across its whole animation.
#include "assets.h"
#include "gpu_test.h"

#include "render/deform_pass.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/procedural_eye.h"
#include "vk/error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

namespace snell::test {
namespace {

/// Deforms at `samples` times spread over the animation (and off its keys)
/// and returns the worst position error relative to each item's extent and
/// the worst normal angle error (1 - cos).
struct Errors {
  double position = 0.0;
  double normal = 0.0;
  size_t itemsChecked = 0;
};

Errors deformAndCompare(vk::Context& context, const scene::Scene& scene, int samples) {
  scene::Pose layout = scene::evaluate(scene, 0.0);
  render::DeformPass pass(context, scene, layout);
  Errors errors;
  double duration = scene::animationDuration(scene);
  vk::Commands commands(context, "deform test");
  vk::UploadArena arena(context, "deform test uploads");
  for (int k = 0; k < samples; ++k) {
    // Spread over [0, duration] but not on round numbers, which tend to be keys.
    double t = duration * (k + 0.37 * (k % 2)) / std::max(samples - 1, 1);
    scene::Pose pose = scene::evaluate(scene, std::min(t, duration));
    commands.begin();
    arena.reset();
    pass.record(commands, pose, arena);
    commands.submitAndWait();
    for (const render::DeformOutput& out : pass.outputs()) {
      const scene::DrawItem& item = pose.items[size_t(out.item)];
      std::vector<glm::dvec3> cpuPositions, cpuNormals;
      scene::deformOnCpu(item, cpuPositions, cpuNormals);
      std::vector<float> gpuPositions(cpuPositions.size() * 3), gpuNormals(cpuNormals.size() * 3);
      VkDeviceSize offset = VkDeviceSize(out.slot.firstVertex) * 12;
      vk::download(context, *out.slot.positions, gpuPositions.data(), gpuPositions.size() * 4, offset);
      vk::download(context, *out.slot.normals, gpuNormals.data(), gpuNormals.size() * 4, offset);
      glm::dvec3 lo(INFINITY), hi(-INFINITY);
      for (const glm::dvec3& p : cpuPositions) lo = glm::min(lo, p), hi = glm::max(hi, p);
      double extent = std::max(glm::length(hi - lo), 1e-30);
      for (size_t v = 0; v < cpuPositions.size(); ++v) {
        // Skinned positions come out relative to the item's anchor.
        glm::dvec3 gp = out.anchor + glm::dvec3(gpuPositions[3 * v], gpuPositions[3 * v + 1], gpuPositions[3 * v + 2]);
        glm::dvec3 gn(gpuNormals[3 * v], gpuNormals[3 * v + 1], gpuNormals[3 * v + 2]);
        errors.position = std::max(errors.position, glm::length(gp - cpuPositions[v]) / extent);
        if (glm::length(cpuNormals[v]) > 0.5) errors.normal = std::max(errors.normal, 1.0 - glm::dot(gn, cpuNormals[v]));
      }
      ++errors.itemsChecked;
    }
  }
  return errors;
}

const std::vector<std::string> kDeformingModels = {
    "SimpleSkin/glTF/SimpleSkin.gltf", "RiggedSimple/glTF-Binary/RiggedSimple.glb",
    "RiggedFigure/glTF-Binary/RiggedFigure.glb", "CesiumMan/glTF-Binary/CesiumMan.glb",
    "RecursiveSkeletons/glTF-Binary/RecursiveSkeletons.glb", "SimpleMorph/glTF/SimpleMorph.gltf",
    "AnimatedMorphCube/glTF-Binary/AnimatedMorphCube.glb", "AnimatedMorphSphere/glTF-Binary/AnimatedMorphSphere.glb",
    "MorphPrimitivesTest/glTF-Binary/MorphPrimitivesTest.glb", "MorphStressTest/glTF-Binary/MorphStressTest.glb"};

TEST(DeformingModels, TheListCoversEveryModelThatDeforms) {
  std::set<std::string> listed;
  for (const std::string& m : kDeformingModels) listed.insert(m.substr(0, m.find('/')));
  for (const auto& folder : std::filesystem::directory_iterator(assetsDir() / "gltf")) {
    for (const auto& entry : std::filesystem::recursive_directory_iterator(folder.path())) {
      std::string ext = entry.path().extension().string();
      if (ext != ".glb" && ext != ".gltf") continue;
      scene::Scene scene;
      try {
        scene = scene::loadGltf(entry.path().string());
      } catch (const scene::SceneError&) {
        continue;  // refused files are the loader tests' business
      }
      scene::Pose pose = scene::evaluate(scene, 0.0);
      bool deforms = std::any_of(pose.items.begin(), pose.items.end(), [](const auto& i) { return i.deforms(); });
      EXPECT_TRUE(!deforms || listed.count(folder.path().filename().string())) << entry.path() << " deforms but is not tested";
    }
  }
}

class DeformingModel : public GpuTest, public ::testing::WithParamInterface<std::string> {};

TEST_P(DeformingModel, GpuMatchesCpuAcrossTheAnimation) {
  scene::Scene scene = scene::loadGltf(model(GetParam()));
  Errors errors = deformAndCompare(context(), scene, 12);
  std::printf("    %s: %zu item deformations, max position error %.2e of extent, max normal error %.2e\n",
              GetParam().c_str(), errors.itemsChecked, errors.position, errors.normal);
  EXPECT_GT(errors.itemsChecked, 0u) << "nothing deformed";
  EXPECT_LE(errors.position, 1e-5) << "max position error relative to the mesh's extent";
  EXPECT_LE(errors.normal, 1e-5) << "max normal error, 1 - cos(angle)";
}

INSTANTIATE_TEST_SUITE_P(Assets, DeformingModel, ::testing::ValuesIn(kDeformingModels), [](const auto& info) {
  return std::filesystem::path(info.param).stem().string();
});

using DeformPassTest = GpuTest;

TEST_F(DeformPassTest, ProceduralEyeAndCrowdMatchCpu) {
  scene::EyeOptions options;
  Errors eye = deformAndCompare(context(), scene::makeEye(options), 8);
  options.crowd = 3;
  options.resolution = 16;
  Errors crowd = deformAndCompare(context(), scene::makeEye(options), 8);
  std::printf("    procedural eye: max position error %.2e, crowd of 3: %.2e (of extent)\n", eye.position, crowd.position);
  EXPECT_EQ(eye.itemsChecked, 8u * 5u);
  EXPECT_LE(eye.position, 1e-5);
  EXPECT_LE(crowd.position, 1e-5);
  EXPECT_LE(eye.normal, 1e-5);
}

TEST_F(DeformPassTest, StaticShapesDoNotRunIt) {
  scene::Scene scene = scene::loadGltf(model("SimpleSparseAccessor/glTF/SimpleSparseAccessor.gltf"));
  render::DeformPass pass(context(), scene, scene::evaluate(scene, 0.0));
  EXPECT_TRUE(pass.outputs().empty());
}

TEST_F(DeformPassTest, RefusesAPoseOfAnotherScene) {
  scene::Scene skin = scene::loadGltf(model("RiggedSimple/glTF-Binary/RiggedSimple.glb"));
  scene::Scene stat = scene::loadGltf(model("SimpleSparseAccessor/glTF/SimpleSparseAccessor.gltf"));
  render::DeformPass pass(context(), skin, scene::evaluate(skin, 0.0));
  vk::Commands commands(context(), "wrong pose");
  vk::UploadArena arena(context(), "wrong pose uploads");
  commands.begin();
  EXPECT_THROW(pass.record(commands, scene::evaluate(stat, 0.0), arena), vk::VulkanError);
  commands.submitAndWait();
}

}  // namespace
}  // namespace snell::test
