// `snell info SCENE` as a user runs it: exit codes and what it prints.
#include "assets.h"
#include "command_run.h"
#include "io/json.h"

#include <gtest/gtest.h>

#include <string>

namespace snell::test {
namespace {

TEST(SceneInfoCommand, DescribesAModelAndExitsZero) {
  CommandRun run = snell("info " + shellQuoted(model("TransmissionRoughnessTest/glTF-Binary/TransmissionRoughnessTest.glb")));
  EXPECT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("refractive"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("ior 2.42"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("GPU memory per frame"), std::string::npos) << run.output;
}

TEST(SceneInfoCommand, MalformedFileExitsNonZeroNamingTheFileAndTheProblem) {
  std::string path = (assetsDir() / "gltf-invalid/node/node_loop.gltf").string();
  CommandRun run = snell("info " + shellQuoted(path));
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find(path), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("cycle"), std::string::npos) << run.output;
}

TEST(SceneInfoCommand, MissingFileExitsNonZero) {
  CommandRun run = snell("info /nonexistent/scene.glb");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("/nonexistent/scene.glb"), std::string::npos) << run.output;
}

TEST(SceneInfoCommand, RequiredExtensionCanBeIgnoredOnRequest) {
  std::string path = shellQuoted(model("IridescenceSuzanne/glTF-Binary/IridescenceSuzanne.glb"));
  EXPECT_EQ(snell("info " + path).exitCode, 1);
  CommandRun run = snell("info " + path + " --ignore-extension KHR_materials_iridescence");
  EXPECT_EQ(run.exitCode, 0) << run.output;
}

TEST(SceneInfoCommand, ReportsTextureMemoryWithMipsAndLoadTimes) {
  CommandRun run = snell("info " + shellQuoted(model("LightsPunctualLamp/glTF/LightsPunctualLamp.gltf")) + " --timings");
  EXPECT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("on the GPU with mips; largest"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("load times: parse"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("image decode"), std::string::npos) << run.output;
}

TEST(SceneInfoCommand, TimingsReportTheVulkanDevicesCreationTime) {
  std::string path = shellQuoted(model("TransmissionTest/glTF-Binary/TransmissionTest.glb"));
  CommandRun text = snell("info " + path + " --timings");
  ASSERT_EQ(text.exitCode, 0) << text.output;
  EXPECT_NE(text.output.find("Vulkan instance and device "), std::string::npos) << text.output;
  CommandRun json = snell("info " + path + " --timings --json -");
  ASSERT_EQ(json.exitCode, 0) << json.output;
  EXPECT_GT(io::Json::parse(json.output).at("load_times").at("device_ms").get<double>(), 0.0) << json.output;
}

TEST(SceneInfoCommand, TimingsReportTheFirstFramesPipelineCompile) {
  CommandRun run = snell("info " + shellQuoted(model("TransmissionTest/glTF-Binary/TransmissionTest.glb")) + " --timings");
  EXPECT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("first frame: "), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(" pipelines (pipeline cache: "), std::string::npos) << run.output;
}

TEST(SceneInfoCommand, ATextureBudgetLoadsLowerMipsAndSaysSo) {
  CommandRun run = snell("info " + shellQuoted(model("LightsPunctualLamp/glTF/LightsPunctualLamp.gltf")) +
                         " --texture-budget 16");
  EXPECT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("over the texture budget of 16.0 MiB"), std::string::npos) << run.output;
  EXPECT_EQ(snell("info " + shellQuoted(model("LightsPunctualLamp/glTF/LightsPunctualLamp.gltf")) +
                  " --texture-budget 0").exitCode, 2);
}

TEST(SceneInfoCommand, BadArgumentsExitTwoWithUsageHint) {
  CommandRun run = snell("info --frobnicate");
  EXPECT_EQ(run.exitCode, 2) << run.output;
  EXPECT_NE(run.output.find("--frobnicate"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("Run 'snell info --help'"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace snell::test
