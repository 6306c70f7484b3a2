// `snell render` as a pipeline engineer runs it: what --stats prints.
#include "assets.h"
#include "command_run.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

namespace snell::test {
namespace {

namespace fs = std::filesystem;

// The first frame of a run builds every tree; --stats says so and counts the
// glass pixels that the masked viewport trace covered.
TEST(RenderCommand, StatsReportTheFirstFramesBuildAndTracedPixels) {
  fs::path out = fs::temp_directory_path() / "snell_render_stats.png";
  CommandRun run = snell("render --eye --viewport --size 96x72 --stats -o " + shellQuoted(out.string()));
  fs::remove(out);
  ASSERT_EQ(run.exitCode, 0) << run.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(run.output, m, std::regex("trees built ([0-9]+)"))) << run.output;
  EXPECT_GT(std::stoul(m[1]), 0u) << run.output;
  ASSERT_TRUE(std::regex_search(run.output, m, std::regex("pixels traced ([0-9]+)"))) << run.output;
  EXPECT_GT(std::stoul(m[1]), 0u) << run.output;
  EXPECT_LT(std::stoul(m[1]), 96u * 72u) << "the masked trace covers the glass, not the image: " << run.output;
  EXPECT_NE(run.output.find("GPU ms:"), std::string::npos) << run.output;
}

// A still glTF measures nothing after its first frame unless the camera moves.
TEST(BenchFrame, OrbitTracesEveryFrameOfAStillScene) {
  std::string scene = shellQuoted(model("TransmissionTest/glTF-Binary/TransmissionTest.glb"));
  CommandRun still = snell("bench frame " + scene + " --viewport --frames 3 --warmup 1 --size 48x32");
  CommandRun orbit = snell("bench frame " + scene + " --viewport --orbit --frames 3 --warmup 1 --size 48x32");
  ASSERT_EQ(orbit.exitCode, 0) << orbit.output;
  EXPECT_NE(orbit.output.find("viewport, masked trace, orbiting"), std::string::npos) << orbit.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(orbit.output, m, std::regex("pixels traced ([0-9]+)"))) << orbit.output;
  EXPECT_GT(std::stoul(m[1]), 0u) << "the median orbiting frame traced glass: " << orbit.output;
  ASSERT_TRUE(std::regex_search(still.output, m, std::regex("pixels traced ([0-9]+)"))) << still.output;
  EXPECT_EQ(std::stoul(m[1]), 0u) << "a still frame redraws nothing: " << still.output;
}

// The hit replay is only a fair measure of the non-traversal work if it draws
// the same picture; bench cost checks that and counts each pixel's work.
TEST(BenchCost, TheHitReplayDrawsTheTracedPictureAndEachPixelsWorkIsCounted) {
  CommandRun run = snell("bench cost --size 64x36 --frames 1");
  ASSERT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("the replay draws the traced picture: yes (0 pixels differ)"), std::string::npos)
      << run.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(run.output, m, std::regex("per pixel: ([0-9.]+) segments .* ([0-9.]+) node visits")))
      << run.output;
  EXPECT_GE(std::stod(m[1]), 1.0) << "every pixel traces at least its camera ray: " << run.output;
  EXPECT_GT(std::stod(m[2]), 0.0) << run.output;
}

// A glTF of no meshes (a file of cameras or lights): its background, as a
// USD stage with nothing to draw; --strict makes it an error.
fs::path writeSceneWithoutMeshes() {
  fs::path file = fs::temp_directory_path() / "snell_no_meshes.gltf";
  std::ofstream(file) << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
                             "nodes": [{"name": "an empty"}]})";
  return file;
}

TEST(RenderCommand, ASceneWithNothingToDrawDrawsItsBackgroundWithANote) {
  fs::path file = writeSceneWithoutMeshes(), out = fs::temp_directory_path() / "snell_no_meshes.png";
  fs::remove(out);
  CommandRun run = snell("render " + shellQuoted(file.string()) + " --size 8x6 -o " + shellQuoted(out.string()));
  EXPECT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find(file.string() + ": nothing to draw: no mesh with triangles; the background is drawn"),
            std::string::npos)
      << run.output;
  EXPECT_TRUE(fs::exists(out));
  fs::remove(out);
}

TEST(RenderCommand, StrictRefusesASceneWithNothingToDrawAndWritesNothing) {
  fs::path file = writeSceneWithoutMeshes(), out = fs::temp_directory_path() / "snell_no_meshes_strict.png";
  fs::remove(out);
  CommandRun run =
      snell("render " + shellQuoted(file.string()) + " --strict --size 8x6 -o " + shellQuoted(out.string()));
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find(file.string() + ": nothing to draw: no mesh with triangles (--strict)"), std::string::npos)
      << run.output;
  EXPECT_FALSE(fs::exists(out));
}

TEST(RenderCommand, TheDefaultMethodIsAutoAndSaysWhatItDrewWith) {
  fs::path out = fs::temp_directory_path() / "snell_render_auto.png";
  CommandRun run = snell("render --eye --size 32x24 -o " + shellQuoted(out.string()));
  fs::remove(out);
  ASSERT_EQ(run.exitCode, 0) << run.output;
  EXPECT_TRUE(std::regex_search(run.output, std::regex("method auto: (trace|driver-rt) \\(")))
      << run.output;
}

// A device slower than the wait limit is reported, not waited on forever:
// the error names the device, the limit and the setting, and writes nothing.
TEST(RenderCommand, AFrameOverTheWaitLimitIsAnErrorNamingTheLimitAndItsSetting) {
  fs::path out = fs::temp_directory_path() / "snell_render_timeout.png";
  CommandRun run = runCommand("SNELL_GPU_TIMEOUT=0.000001 " + std::string(SNELL_BINARY) +
                              " render --eye --method trace --size 320x240 -o " + shellQuoted(out.string()));
  EXPECT_NE(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("did not finish within 1e-06 s (SNELL_GPU_TIMEOUT=0.000001)"), std::string::npos)
      << run.output;
  EXPECT_FALSE(fs::exists(out));
}

TEST(RenderCommand, AWaitLimitThatIsNotANumberOfSecondsIsAClearError) {
  CommandRun run = runCommand("SNELL_GPU_TIMEOUT=soon " + std::string(SNELL_BINARY) + " render --eye --size 8x8 -o " +
                              shellQuoted((fs::temp_directory_path() / "snell_never.png").string()));
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("SNELL_GPU_TIMEOUT=soon: expected seconds"), std::string::npos) << run.output;
}

TEST(SnellCommand, VersionPrintsTheVersionAndExitsZero) {
  CommandRun run = snell("--version");
  EXPECT_EQ(run.exitCode, 0) << run.output;
  EXPECT_TRUE(std::regex_search(run.output, std::regex("^snell [0-9]+\\.[0-9]+\\.[0-9]+\n$"))) << run.output;
}

TEST(RenderCommand, StatsWithTheCpuReferenceIsAUsageError) {
  CommandRun run = snell("render --eye --reference --stats -o /tmp/never_written.png");
  EXPECT_EQ(run.exitCode, 2) << run.output;
  EXPECT_FALSE(fs::exists("/tmp/never_written.png"));
}

}  // namespace
}  // namespace snell::test
