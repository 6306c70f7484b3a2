// What a failing GPU, a full device and an unwritable path do to snell's
// commands: a clear error naming the problem, a non-zero exit, and no file
// (or half a file) left behind. The GPU's failures come from the fault switch
// (SNELL_FAULT, src/vk/error.h), the full device from SNELL_DEVICE_MEMORY_LIMIT.
// The test command runs these under AddressSanitizer as well.
#include "command_run.h"
#include "gpu_test.h"

#include "io/image_file.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/procedural_eye.h"
#include "vk/context.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <filesystem>
#include <string>
#include <vector>

namespace snell::test {
namespace {

namespace fs = std::filesystem;

// In the sanitized build a command checks for leaks at exit, and a leak
// changes its exit code to 1; elsewhere the variable does nothing. The driver
// stays loaded (tests/tools/keep_libraries_loaded.cpp), so only snell's own
// leaks count.
const std::string kLeakCheck = std::string("ASAN_OPTIONS=detect_leaks=1 LD_PRELOAD=") + SNELL_KEEP_LOADED + " ";

// A private folder per test: whatever a failed run leaves in it is visible.
class Robustness : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("snell-robustness-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  CommandRun snell(const std::string& environment, const std::string& arguments) const {
    return runCommand("cd " + shellQuoted(dir_.string()) + " && " + kLeakCheck + environment + " " + SNELL_BINARY +
                      " " + arguments);
  }
  size_t filesLeft() const { return size_t(std::distance(fs::directory_iterator(dir_), fs::directory_iterator())); }

  fs::path dir_;
};

TEST_F(Robustness, DeviceLostAtSubmitEndsRenderWithExitThreeAndNoImage) {
  CommandRun run = snell("SNELL_FAULT=vkQueueSubmit:VK_ERROR_DEVICE_LOST", "render --eye --size 64x48 -o eye.png");
  EXPECT_EQ(run.exitCode, 3) << "a farm retries exit 3 on another node: " << run.output;
  EXPECT_NE(run.output.find("vkQueueSubmit"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("VK_ERROR_DEVICE_LOST"), std::string::npos) << run.output;
  EXPECT_EQ(filesLeft(), 0u) << run.output;
}

TEST_F(Robustness, DeviceLostWhileWaitingEndsAnAnimationWithTheFramesBeforeItWhole) {
  // The first frames are written whole; the failing one leaves nothing.
  CommandRun run = snell("SNELL_FAULT=vkWaitForFences:VK_ERROR_DEVICE_LOST:6",
                         "render --eye --size 48x36 --frames 1:8 -o 'eye_####.png'");
  EXPECT_EQ(run.exitCode, 3) << run.output;
  EXPECT_NE(run.output.find("VK_ERROR_DEVICE_LOST"), std::string::npos) << run.output;
  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_EQ(entry.path().filename().string().rfind("eye_", 0), 0u) << "a temporary file was left: " << entry.path();
    EXPECT_GT(fs::file_size(entry.path()), 100u) << entry.path();
  }
  EXPECT_LT(filesLeft(), 8u) << run.output;
}

TEST_F(Robustness, SigtermDuringTheThirdFrameKeepsTwoWholeFramesAndExits143) {
  // Slurm's scancel and time limit send SIGTERM; it arrives while frame 3 of 6
  // is on the GPU (frames this size take a good part of a second on lavapipe).
  CommandRun run = runCommand(
      "cd " + shellQuoted(dir_.string()) + " && { " + kLeakCheck + SNELL_BINARY +
      " render --eye --size 960x720 --frames 1-6 -o 'f_#.png' & pid=$!; "
      "for i in $(seq 20000); do [ -e f_2.png ] && break; sleep 0.002; done; kill -TERM $pid; wait $pid; "
      "echo \"exit $?\"; }");
  EXPECT_NE(run.output.find("exit 143"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("stopped by signal 15"), std::string::npos) << run.output;
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir_)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"f_1.png", "f_2.png"})) << "no partial or temporary file: " << run.output;
  for (const std::string& name : names) EXPECT_GT(fs::file_size(dir_ / name), 1000u) << name;
}

// Nothing to draw is not a mistake: the picture is the background, and no
// step of the frame reads the empty tables it has (the sanitizers watch).
TEST_F(Robustness, ASceneWithoutAMeshRendersItsBackground) {
  std::ofstream((dir_ / "empty.gltf").string())
      << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"name":"nothing here"}]})";
  for (std::string mode : {"", "--viewport "}) {
    CommandRun run = snell("", "render empty.gltf " + mode + "--size 32x24 --background 0.25,0.5,1 -o empty.png");
    ASSERT_EQ(run.exitCode, 0) << mode << run.output;
    io::PngRgba png = io::readPngRgba((dir_ / "empty.png").string());
    ASSERT_EQ(png.width * png.height, 32u * 24u);
    for (uint32_t p = 0; p < png.width * png.height; ++p) {
      ASSERT_EQ(png.rgba8[4 * p + 2], 255) << mode << "pixel " << p << " is not the background";
    }
  }
}

TEST_F(Robustness, AFailedAllocationNamesWhatWasBeingAllocated) {
  CommandRun run = snell("SNELL_FAULT=vkAllocateMemory:VK_ERROR_OUT_OF_DEVICE_MEMORY:12",
                         "render --eye --viewport --size 64x48 -o eye.png");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("allocating"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("for '"), std::string::npos) << "names the buffer or image: " << run.output;
  EXPECT_NE(run.output.find("VK_ERROR_OUT_OF_DEVICE_MEMORY"), std::string::npos) << run.output;
  EXPECT_EQ(filesLeft(), 0u) << run.output;
}

TEST_F(Robustness, ASceneTooBigForTheDeviceIsRefusedWithTheNumbersBeforeAnythingIsAllocated) {
  CommandRun run = snell("SNELL_DEVICE_MEMORY_LIMIT=65536", "render --eye --size 64x48 -o eye.png");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("procedural eye"), std::string::npos) << "names the scene: " << run.output;
  EXPECT_NE(run.output.find("needs"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("of the 0.1 MiB limit is free"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("SNELL_DEVICE_MEMORY_LIMIT"), std::string::npos) << run.output;
  EXPECT_EQ(filesLeft(), 0u);
}

TEST_F(Robustness, AnImageTooBigForTheDeviceIsRefusedNamingTheView) {
  // 64 MiB holds the eye, not a 4000x4000 view's images (16 million pixels).
  CommandRun run = snell("SNELL_DEVICE_MEMORY_LIMIT=67108864", "render --eye --size 4000x4000 -o eye.png");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("view 0 at 4000x4000 needs"), std::string::npos) << run.output;
  EXPECT_EQ(filesLeft(), 0u);
}

TEST_F(Robustness, AMalformedFaultSettingIsAnErrorSayingWhatIsExpected) {
  CommandRun run = snell("SNELL_FAULT=vkQueueSubmit:DEVICE_LOST", "render --eye --size 16x16 -o eye.png");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("expected vkCALL:VK_ERROR_"), std::string::npos) << run.output;
}

TEST_F(Robustness, AMalformedMemoryLimitIsAnErrorNamingTheVariable) {
  CommandRun run = snell("SNELL_DEVICE_MEMORY_LIMIT=lots", "render --eye --size 16x16 -o eye.png");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("SNELL_DEVICE_MEMORY_LIMIT=lots"), std::string::npos) << run.output;
}

TEST_F(Robustness, AnOutputInAMissingFolderFailsBeforeRendering) {
  CommandRun run = snell("", "render --eye --size 64x48 --stats -o missing/eye.png");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("missing/eye.png: the folder missing does not exist"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("GPU ms"), std::string::npos) << "nothing was rendered: " << run.output;
}

TEST_F(Robustness, AnOutputThatIsAFolderFailsBeforeRendering) {
  fs::create_directory(dir_ / "eye.png");
  CommandRun run = snell("", "bake --eye --size 32x32 -o eye.png");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("eye.png: is a folder"), std::string::npos) << run.output;
}

TEST_F(Robustness, AReadOnlyFolderFailsBeforeRendering) {
  if (::geteuid() == 0) GTEST_SKIP() << "root writes into read-only folders";
  fs::create_directory(dir_ / "locked");
  fs::permissions(dir_ / "locked", fs::perms::owner_read | fs::perms::owner_exec);
  CommandRun run = snell("", "render --eye --size 16x16 -o locked/eye.png");
  fs::permissions(dir_ / "locked", fs::perms::owner_all);
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("cannot write in the folder"), std::string::npos) << run.output;
}

TEST_F(Robustness, DeviceLostDuringBakeLeavesNoMap) {
  CommandRun run = snell("SNELL_FAULT=vkQueueSubmit:VK_ERROR_DEVICE_LOST:2", "bake --eye --size 32x32 -o map.png");
  EXPECT_EQ(run.exitCode, 3) << run.output;
  EXPECT_NE(run.output.find("VK_ERROR_DEVICE_LOST"), std::string::npos) << run.output;
  EXPECT_EQ(filesLeft(), 0u) << run.output;
}

TEST_F(Robustness, DeviceLostDuringExportWebLeavesNoFolder) {
  CommandRun run = snell("SNELL_FAULT=vkQueueSubmit:VK_ERROR_DEVICE_LOST:3", "export-web --eye --size 32x32 -o page");
  EXPECT_EQ(run.exitCode, 3) << run.output;
  EXPECT_EQ(filesLeft(), 0u) << run.output;
}

TEST_F(Robustness, DeviceLostDuringABenchmarkLeavesNoJson) {
  CommandRun run = snell("SNELL_FAULT=vkQueueSubmit:VK_ERROR_DEVICE_LOST:4",
                         "bench frame --eye-resolution 16 --frames 4 --json frame.json");
  EXPECT_EQ(run.exitCode, 3) << run.output;
  EXPECT_NE(run.output.find("VK_ERROR_DEVICE_LOST"), std::string::npos) << run.output;
  EXPECT_EQ(filesLeft(), 0u) << run.output;
}

#ifdef SNELL_VIEWER_BINARY
TEST_F(Robustness, DeviceLostEndsTheViewersDrawingWithAnErrorAndNoScreenshot) {
  CommandRun run = runCommand("cd " + shellQuoted(dir_.string()) +
                              " && " + kLeakCheck + "SNELL_FAULT=vkQueueSubmit:VK_ERROR_DEVICE_LOST:16 " +
                              SNELL_VIEWER_BINARY + " --offscreen --size 48x36 --frames 30 --screenshot shot.png");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("the GPU failed, so nothing more is drawn"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("VK_ERROR_DEVICE_LOST"), std::string::npos) << run.output;
  EXPECT_EQ(filesLeft(), 0u) << run.output;
}
#endif

// The accounting behind the limit: what a renderer allocates it gives back.
TEST(DeviceMemory, EveryByteARendererAllocatedIsCountedAndReturned) {
  vk::Context& context = gpuContext();
  context.collectRetired();
  uint64_t before = context.memoryInUse();
  scene::Scene eye = scene::makeEye({.resolution = 16});
  scene::Pose pose = scene::evaluate(eye, 0.0);
  uint64_t allocated = 0;
  {
    render::Renderer renderer(context, eye, pose);
    EXPECT_GT(context.memoryInUse(), before);
    allocated = context.memoryInUse() - before;
    EXPECT_LE(context.memoryInUse(), context.memoryLimit());
    EXPECT_GE(context.memoryPeak(), context.memoryInUse());
  }
  vkDeviceWaitIdle(context.device());
  context.collectRetired();
  EXPECT_EQ(context.memoryInUse(), before) << allocated << " bytes were allocated";
}

}  // namespace
}  // namespace snell::test
