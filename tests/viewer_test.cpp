// snell-view as a user runs it, in a window under Xvfb (lavapipe, validation
// on: the viewer exits 1 on any validation message).
#include "assets.h"
#include "command_run.h"
#include "golden_support.h"

#include "cli/image_file.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <filesystem>
#include <string>

namespace snell::test {
namespace {

namespace fs = std::filesystem;

// A private X server per run; the viewer needs nothing else from the machine.
std::string underXvfb(const std::string& arguments) {
  return "xvfb-run -a -s '-screen 0 1280x1024x24' " + std::string(SNELL_VIEWER_BINARY) + " " + arguments;
}

CommandRun view(const std::string& arguments) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0) {
    return {-1, "xvfb-run is not installed (Debian 12: apt-get install xvfb xauth; scripts/bootstrap test does)"};
  }
  return runCommand(underXvfb(arguments));
}

// The viewer's 30th frame, overlays hidden, is what `snell render --viewport`
// writes for the same camera and size: the same frame code, through a window.
// Tolerance: every pixel within 1/255 (they share every pass; only the sRGB
// encoding differs, GPU in the viewer, CPU in snell render). Measured: identical.
TEST(Viewer, ThirtyFramesUnderXvfbMatchTheViewportRender) {
  fs::path dir = scratchDir("viewer-screenshot");
  std::string shot = (dir / "viewer.png").string(), render = (dir / "render.png").string();
  CommandRun run = view("--frames 30 --size 192x144 --hide-ui --screenshot " + shellQuoted(shot));
  ASSERT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("30 frames"), std::string::npos) << run.output;
  CommandRun reference = runCommand(std::string(SNELL_BINARY) + " render --eye --viewport --size 192x144 -o " +
                                    shellQuoted(render));
  ASSERT_EQ(reference.exitCode, 0) << reference.output;
  Comparison result = compare(cli::readRgb8(shot), cli::readRgb8(render));
  EXPECT_EQ(result.withinOne, result.pixels) << result.firstMismatches;
  EXPECT_LE(result.maxDifference, 1);
}

// A method picked on the command line is what `snell render --method` draws.
TEST(Viewer, AScreenSpaceMethodMatchesTheRenderOfTheSameMethod) {
  fs::path dir = scratchDir("viewer-method");
  std::string shot = (dir / "viewer.png").string(), render = (dir / "render.png").string();
  CommandRun run = view("--frames 3 --size 160x120 --hide-ui --method normal-offset --screenshot " + shellQuoted(shot));
  ASSERT_EQ(run.exitCode, 0) << run.output;
  CommandRun reference = runCommand(std::string(SNELL_BINARY) +
                                    " render --eye --method normal-offset --size 160x120 -o " + shellQuoted(render));
  ASSERT_EQ(reference.exitCode, 0) << reference.output;
  Comparison result = compare(cli::readRgb8(shot), cli::readRgb8(render));
  EXPECT_EQ(result.withinOne, result.pixels) << result.firstMismatches;
}

// Resize (down to 1x1), orbit, pan, dolly, refraction off and on, wireframe,
// heat map, scrubbing and playing, two viewports, the film back's pan and
// zoom, a glTF camera, minimise and restore: the viewer stays alive, recreates
// its swapchain and the validation layer stays silent.
TEST(Viewer, SurvivesAScriptedSessionWithValidationSilent) {
  fs::path dir = scratchDir("viewer-script");
  std::string shot = (dir / "last.png").string();
  CommandRun run = view("--frames 30 --size 384x288 --script " +
                        shellQuoted(std::string(SNELL_SOURCE_DIR) + "/tests/data/viewer_session.script") +
                        " --screenshot " + shellQuoted(shot));
  ASSERT_EQ(run.exitCode, 0) << run.output;
  EXPECT_EQ(run.output.find("[vulkan"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("frame 26: resize 360 240"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("swapchain recreated 0 time"), std::string::npos) << "no resize reached the swapchain\n"
                                                                               << run.output;
  cli::Rgb8Image last = cli::readRgb8(shot);
  EXPECT_EQ(last.width, 360u);
  EXPECT_EQ(last.height, 240u);
}

TEST(Viewer, OpensAglTFFileGivenOnTheCommandLineInTwoViewports) {
  CommandRun run = view(shellQuoted(model("TransmissionRoughnessTest/glTF-Binary/TransmissionRoughnessTest.glb")) +
                        " --frames 3 --size 320x180 --split");
  EXPECT_EQ(run.exitCode, 0) << run.output;
}

// What a file dropped on the window goes through: a file that fails to load
// is reported and the current scene stays; a good one replaces it.
TEST(Viewer, AFailedLoadKeepsTheCurrentSceneAndAGoodOneReplacesIt) {
  fs::path script = scratchDir("viewer-load") / "load.script";
  {
    std::ofstream out(script);
    out << "1 load /nonexistent/dropped.glb\n"
        << "2 load " << model("TransmissionRoughnessTest/glTF-Binary/TransmissionRoughnessTest.glb") << "\n";
  }
  CommandRun run = runCommand("env -u DISPLAY " + std::string(SNELL_VIEWER_BINARY) +
                              " --offscreen --frames 4 --size 160x90 --script " + shellQuoted(script.string()));
  EXPECT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("/nonexistent/dropped.glb"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("opened " + model("TransmissionRoughnessTest/glTF-Binary/TransmissionRoughnessTest.glb")),
            std::string::npos)
      << run.output;
  EXPECT_EQ(run.output.find("[vulkan"), std::string::npos) << run.output;
}

TEST(Viewer, RunsItsFrameCodeOffscreenWithoutADisplay) {
  fs::path dir = scratchDir("viewer-offscreen");
  std::string shot = (dir / "offscreen.png").string(), json = (dir / "times.json").string();
  CommandRun run = runCommand("env -u DISPLAY " + std::string(SNELL_VIEWER_BINARY) + " --offscreen --frames 3 --size 96x64" +
                              " --hide-ui --screenshot " + shellQuoted(shot) + " --json " + shellQuoted(json));
  ASSERT_EQ(run.exitCode, 0) << run.output;
  EXPECT_TRUE(fs::exists(shot));
  EXPECT_TRUE(fs::exists(json));
  EXPECT_NE(run.output.find("GPU total"), std::string::npos) << run.output;
}

TEST(Viewer, MalformedSceneExitsOneNamingTheFileBeforeAnyWindow) {
  std::string path = (assetsDir() / "gltf-invalid/node/node_loop.gltf").string();
  CommandRun run = runCommand("env -u DISPLAY " + std::string(SNELL_VIEWER_BINARY) + " " + shellQuoted(path) + " --frames 1");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find(path), std::string::npos) << run.output;
}

TEST(Viewer, WithoutADisplayItSaysSoAndSuggestsOffscreen) {
  CommandRun run = runCommand("env -u DISPLAY -u WAYLAND_DISPLAY " + std::string(SNELL_VIEWER_BINARY) + " --frames 1");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("--offscreen"), std::string::npos) << run.output;
}

TEST(Viewer, BadArgumentsExitTwo) {
  EXPECT_EQ(runCommand(std::string(SNELL_VIEWER_BINARY) + " --screenshot x.png").exitCode, 2);
  EXPECT_EQ(runCommand(std::string(SNELL_VIEWER_BINARY) + " --offscreen").exitCode, 2);
  fs::path bad = scratchDir("viewer-bad-script") / "bad.script";
  { std::ofstream(bad) << "3 tumble 10 10\n"; }
  CommandRun run = runCommand(std::string(SNELL_VIEWER_BINARY) + " --offscreen --frames 1 --script " + shellQuoted(bad.string()));
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("bad.script:1: unknown action 'tumble'"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace snell::test
