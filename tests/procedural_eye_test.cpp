// `snell eye`: the written file reads back as the eye the issue describes,
// passes the Khronos glTF validator, and deforms on the GPU like on the CPU.
#include "assets.h"
#include "command_run.h"

#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/gltf_writer.h"
#include "scene/procedural_eye.h"
#include "scene/scene_summary.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <set>

namespace snell::test {
namespace {

using scene::EyeOptions;

scene::Scene writeAndRead(const EyeOptions& options, const std::string& name) {
  std::string path = (scratchDir("eye-" + name) / (name + ".glb")).string();
  scene::saveGltf(scene::makeEye(options), path);
  return scene::loadGltf(path);
}

TEST(ProceduralEye, CorneaIsOneMeshWithATransmissiveTipAndOpaqueRest) {
  scene::Scene eye = writeAndRead({}, "default");
  const scene::Mesh* cornea = nullptr;
  for (const scene::Mesh& m : eye.meshes) {
    if (m.name == "cornea") cornea = &m;
  }
  ASSERT_NE(cornea, nullptr);
  ASSERT_EQ(cornea->shapes.size(), 2u);
  std::set<bool> refractive;
  for (int s : cornea->shapes) {
    const scene::Material& material = eye.materials.at(size_t(eye.shapes[size_t(s)].material));
    refractive.insert(material.refractive());
    if (material.refractive()) {
      EXPECT_FLOAT_EQ(material.ior, 1.376f);
      EXPECT_FLOAT_EQ(material.transmission, 1.0f);
    }
  }
  EXPECT_EQ(refractive, (std::set<bool>{false, true}));
  EXPECT_EQ(scene::summarize(eye).refractiveMaterials, 1u);
}

TEST(ProceduralEye, HasMorphsAJointAClipACameraTwoLightsAndAnIrisTexture) {
  scene::Scene eye = writeAndRead({}, "rig");
  for (const scene::Shape& s : eye.shapes) {
    EXPECT_EQ(s.targets.size(), 2u) << s.name;  // squash, dilate
    EXPECT_TRUE(s.skinned()) << s.name;
  }
  EXPECT_EQ(eye.skins.size(), 1u);
  ASSERT_EQ(eye.animations.size(), 1u);
  EXPECT_FLOAT_EQ(eye.animations[0].duration, 4.0f);
  EXPECT_EQ(eye.cameras.size(), 1u);
  EXPECT_EQ(eye.lights.size(), 2u);
  ASSERT_EQ(eye.textures.size(), 1u);
  EXPECT_EQ(eye.textures[0].width, 256u);
}

TEST(ProceduralEye, OptionsReachTheFile) {
  EyeOptions options;
  options.ior = 1.5f;
  scene::Scene eye = writeAndRead(options, "ior");
  for (const scene::Material& m : eye.materials) {
    if (m.refractive()) {
      EXPECT_FLOAT_EQ(m.ior, 1.5f);
    }
  }
}

TEST(ProceduralEye, ResolutionReachesHundredsOfThousandsOfTriangles) {
  EyeOptions options;
  options.resolution = 256;
  EXPECT_GT(scene::summarize(scene::makeEye(options)).triangles, 150000u);
}

TEST(ProceduralEye, CrowdHasTwoEyesPerCharacterWithStaggeredClips) {
  EyeOptions options;
  options.crowd = 5;
  options.resolution = 16;
  scene::Scene crowd = writeAndRead(options, "crowd");
  EXPECT_EQ(crowd.skins.size(), 10u);
  std::set<float> starts;
  for (const scene::AnimationSampler& s : crowd.animations.at(0).samplers) starts.insert(s.times.front());
  EXPECT_GE(starts.size(), 5u) << "characters should not all start their clip together";
}

// Each eye of a crowd sits where its character's head puts it (the skin's
// inverse bind once undid that and stacked every eye at the origin).
TEST(ProceduralEye, EveryEyeOfACrowdStandsApartFromTheOthers) {
  EyeOptions options;
  options.crowd = 4;
  options.resolution = 8;
  scene::Scene crowd = scene::makeEye(options);
  scene::Pose pose = scene::evaluate(crowd, 0.0);
  std::vector<glm::dvec3> centres;
  for (const scene::DrawItem& item : pose.items) {
    if (crowd.shapes[size_t(item.shape)].name != "sclera") continue;
    std::vector<glm::dvec3> positions, normals;
    scene::deformOnCpu(item, positions, normals);
    glm::dvec3 sum(0.0);
    for (const glm::dvec3& p : positions) sum += p;
    centres.push_back(sum / double(positions.size()));
  }
  ASSERT_EQ(centres.size(), 8u);
  for (size_t a = 0; a < centres.size(); ++a) {
    for (size_t b = a + 1; b < centres.size(); ++b) {
      EXPECT_GT(glm::length(centres[a] - centres[b]), 0.05) << "eyes " << a << " and " << b << " overlap";
    }
  }
}

TEST(ProceduralEye, OutOfRangeOptionsAreRefusedByName) {
  EyeOptions bad;
  bad.ior = 0.9f;
  EXPECT_THROW(scene::checkEyeOptions(bad), std::invalid_argument);
  bad = {};
  bad.resolution = 4;
  try {
    scene::checkEyeOptions(bad);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--resolution"), std::string::npos);
  }
}

TEST(ProceduralEye, FailedWriteLeavesNoFile) {
  std::string path = "/nonexistent-snell-dir/eye.glb";
  EXPECT_THROW(scene::saveGltf(scene::makeEye(), path), scene::SceneError);
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(path + ".partial"));
}

/// Runs tests/tools/validate_gltf.js (the npm gltf-validator) on a file.
int validate(const std::string& path, std::string& output) {
  CommandRun run = runCommand("NODE_PATH='" + std::string(SNELL_GLTF_VALIDATOR_DIR) + "' node '" + SNELL_SOURCE_DIR +
                              "/tests/tools/validate_gltf.js' '" + path + "'");
  output += run.output;
  return run.exitCode;
}

TEST(ProceduralEye, PassesTheKhronosValidatorWithNoErrorOrWarning) {
  ASSERT_TRUE(std::filesystem::exists(std::string(SNELL_GLTF_VALIDATOR_DIR) + "/gltf-validator"))
      << "gltf-validator is not installed in " << SNELL_GLTF_VALIDATOR_DIR << " (scripts/bootstrap test installs it)";
  auto dir = scratchDir("eye-validator");
  std::vector<std::pair<std::string, EyeOptions>> cases = {{"default", {}}};
  EyeOptions crowd;
  crowd.crowd = 3;
  crowd.resolution = 8;
  cases.push_back({"crowd", crowd});
  EyeOptions extreme;
  extreme.ior = 1.0f;
  extreme.irisDepth = 0.0f;
  extreme.corneaBulge = 0.005f;
  cases.push_back({"extreme", extreme});
  EyeOptions aqueous;  // SNELL_materials_priority on the aqueous: an extension the validator does not know, not an error
  aqueous.aqueous = true;
  cases.push_back({"aqueous", aqueous});
  for (const auto& [name, options] : cases) {
    std::string path = (dir / (name + ".glb")).string();
    scene::saveGltf(scene::makeEye(options), path);
    std::string output;
    EXPECT_EQ(validate(path, output), 0) << output;
    EXPECT_NE(output.find("0 errors, 0 warnings"), std::string::npos) << output;
  }
}

}  // namespace
}  // namespace snell::test
