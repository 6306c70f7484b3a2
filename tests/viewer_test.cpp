// snell-view as a user runs it, in a window under Xvfb (lavapipe, validation
// on: the viewer exits 1 on any validation message).
#include "assets.h"
#include "command_run.h"
#include "golden_support.h"

#include "io/image_file.h"
#include "io/json.h"
#include "io/version.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <fstream>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace snell::test {
namespace {

namespace fs = std::filesystem;

// A private X server per run; the viewer needs nothing else from the machine.
std::string underXvfb(const std::string& arguments) {
  return "xvfb-run -a -s '-screen 0 1280x1024x24' " + std::string(SNELL_VIEWER_BINARY) + " " + arguments;
}

// snell-view with no display: a run that gets past parsing by mistake fails
// fast instead of opening a window.
CommandRun headless(const std::string& arguments) {
  return runCommand("env -u DISPLAY -u WAYLAND_DISPLAY " + std::string(SNELL_VIEWER_BINARY) + " " + arguments);
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
  Comparison result = compare(io::readRgb8(shot), io::readRgb8(render));
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
  Comparison result = compare(io::readRgb8(shot), io::readRgb8(render));
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
  io::Rgb8Image last = io::readRgb8(shot);
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

// Every bad value is a usage error (exit 2) that names its option and points to --help.
TEST(Viewer, BadOptionValuesExitTwoNamingTheOption) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--size 0x5", "--size"},
      {"--size 640", "--size"},
      {"--method bogus", "--method"},
      {"--frames abc", "--frames"},
      {"--frames 0", "--frames"},
      {"--camera 2000000", "--camera"},
      {"--camera -1", "--camera"},
      {"--time -1", "--time"},
      {"--time soon", "--time"},
      {"--texture-budget 0", "--texture-budget"},
      {"--frames 1 --screenshot shot.jpg", "--screenshot"},
      {"--json times.json", "--json"},
      {"--offscreen", "--offscreen"},
      {"--no-such-option", "--no-such-option"},
  };
  for (const auto& [arguments, option] : cases) {
    CommandRun run = headless(arguments);
    EXPECT_EQ(run.exitCode, 2) << arguments << "\n" << run.output;
    EXPECT_NE(run.output.find(option), std::string::npos) << arguments << "\n" << run.output;
    EXPECT_NE(run.output.find("Run 'snell-view --help'"), std::string::npos) << arguments << "\n" << run.output;
  }
}

// A camera the scene lacks is found once the scene is loaded: still bad usage.
TEST(Viewer, ACameraTheSceneLacksExitsTwo) {
  CommandRun run = headless("--offscreen --frames 1 --size 64x48 --camera 7");
  EXPECT_EQ(run.exitCode, 2) << run.output;
  EXPECT_NE(run.output.find("--camera 7: the scene has"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("Run 'snell-view --help'"), std::string::npos) << run.output;
}

TEST(Viewer, HelpListsTheOptionsAndKeysAndVersionNamesTheRelease) {
  CommandRun help = headless("--help");
  EXPECT_EQ(help.exitCode, 0) << help.output;
  for (const char* text : {"--frames", "--screenshot", "--method", "--device", "--quiet", "F12", "exit codes"}) {
    EXPECT_NE(help.output.find(text), std::string::npos) << text << "\n" << help.output;
  }
  CommandRun version = headless("--version");
  EXPECT_EQ(version.exitCode, 0) << version.output;
  EXPECT_EQ(version.output, std::string("snell-view ") + io::version() + "\n");
}

// --quiet: nothing at all on standard output (the summary, the memory
// samples and "wrote" lines go); without it they are there.
TEST(Viewer, QuietPrintsNothingOnStandardOutput) {
  fs::path dir = scratchDir("viewer-quiet");
  std::string json = (dir / "times.json").string();
  std::string stdoutOnly = "( env -u DISPLAY -u WAYLAND_DISPLAY " + std::string(SNELL_VIEWER_BINARY) +
                           " --offscreen --frames 3 --size 64x48 --json " + shellQuoted(json);
  CommandRun quiet = runCommand(stdoutOnly + " --quiet 2>/dev/null )");
  EXPECT_EQ(quiet.exitCode, 0);
  EXPECT_EQ(quiet.output, "");
  EXPECT_TRUE(fs::exists(json)) << "--quiet silences the output, not the files";
  CommandRun loud = runCommand(stdoutOnly + " 2>/dev/null )");
  EXPECT_EQ(loud.exitCode, 0);
  EXPECT_NE(loud.output.find("frames in"), std::string::npos) << loud.output;
}

// The --json report: the common head (schema, version, device) and a scene
// name with a quote, a backslash and letters outside ASCII, as valid JSON.
TEST(Viewer, JsonReportCarriesTheHeadAndAnAwkwardSceneNameParses) {
  fs::path dir = scratchDir("viewer-json");
  fs::path scene = dir / ("eye \"quoted\" back\\slash \xc3\xbc" "n" "\xc3\xaf.glb");
  fs::copy_file(model("TransmissionRoughnessTest/glTF-Binary/TransmissionRoughnessTest.glb"), scene);
  std::string json = (dir / "times.json").string();
  CommandRun run = headless(shellQuoted(scene.string()) + " --offscreen --frames 4 --size 64x48 --json " +
                            shellQuoted(json));
  ASSERT_EQ(run.exitCode, 0) << run.output;
  std::ifstream in(json);
  ASSERT_TRUE(in) << json;
  nlohmann::json report;
  ASSERT_NO_THROW(report = nlohmann::json::parse(in)) << "not valid JSON: " << json;
  EXPECT_EQ(report.value("schema", ""), "snell.view/1");
  EXPECT_EQ(report.value("snell_version", ""), io::version());
  ASSERT_TRUE(report.contains("device") && report["device"].is_object()) << report.dump(2);
  EXPECT_FALSE(report["device"].value("name", "").empty()) << report.dump(2);
  EXPECT_EQ(report.value("scene", ""), scene.string());
  EXPECT_EQ(report.value("frames", 0), 4);
  EXPECT_EQ(report.value("width", 0), 64);
  EXPECT_TRUE(report["median_pass_ms"].is_object()) << report.dump(2);
  ASSERT_TRUE(report["memory_samples"].is_array() && !report["memory_samples"].empty()) << report.dump(2);
  EXPECT_EQ(report["memory_samples"][0].value("scene", ""), scene.string());
}

// The screenshot key's file (here through the script's `screenshot`, which
// does what F12 does): snell-view-YYYYMMDD-HHMMSS.png in the current folder,
// the frame as drawn.
TEST(Viewer, TheScreenshotKeyWritesATimestampedPngInTheCurrentFolder) {
  fs::path dir = scratchDir("viewer-screenshot-key");
  { std::ofstream(dir / "shot.script") << "1 screenshot\n"; }
  CommandRun run = runCommand("cd " + shellQuoted(dir.string()) + " && env -u DISPLAY -u WAYLAND_DISPLAY " +
                              std::string(SNELL_VIEWER_BINARY) + " --offscreen --frames 3 --size 80x60 --script shot.script");
  ASSERT_EQ(run.exitCode, 0) << run.output;
  std::vector<fs::path> shots;
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    std::string name = e.path().filename().string();
    if (name.rfind("snell-view-", 0) == 0 && e.path().extension() == ".png") shots.push_back(e.path());
  }
  ASSERT_EQ(shots.size(), 1u) << run.output;
  // snell-view-YYYYMMDD-HHMMSS.png
  EXPECT_EQ(shots[0].filename().string().size(), std::string("snell-view-20240101-120000.png").size()) << shots[0];
  EXPECT_NE(run.output.find("wrote snell-view-"), std::string::npos) << run.output;
  io::Rgb8Image image = io::readRgb8(shots[0].string());
  EXPECT_EQ(image.width, 80u);
  EXPECT_EQ(image.height, 60u);
}

}  // namespace
}  // namespace snell::test
