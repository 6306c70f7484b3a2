// Frames as farms name them, and a shot cut into a farm's tasks: the frame
// lists and name patterns of `snell render --frames`, --skip-existing and
// --stats-json, and the plan and check behind `snell farm`. The Slurm and
// Open Job Description commands themselves run in tests/farm/.
#include "command_run.h"

#include "farm/frames.h"
#include "farm/plan.h"
#include "cli/options.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace snell::test {
namespace {

namespace fs = std::filesystem;
using farm::FrameList;

std::vector<long> framesOf(const std::string& list) { return FrameList::parse("--frames", list).frames; }

std::string usageErrorOf(const std::string& list) {
  try {
    FrameList::parse("--frames", list);
  } catch (const std::invalid_argument& e) {
    return std::string(e.what());
  }
  return "";
}

TEST(FrameList, ReadsEveryFormFarmsWrite) {
  EXPECT_EQ(framesOf("1:9:4"), (std::vector<long>{1, 5, 9}));
  EXPECT_EQ(framesOf("1:3"), (std::vector<long>{1, 2, 3}));
  EXPECT_EQ(framesOf("1-9x4"), (std::vector<long>{1, 5, 9}));
  EXPECT_EQ(framesOf("1-9:4"), (std::vector<long>{1, 5, 9})) << "Open Job Description's step";
  EXPECT_EQ(framesOf("1001-1003"), (std::vector<long>{1001, 1002, 1003}));
  EXPECT_EQ(framesOf("1,5,10-12"), (std::vector<long>{1, 5, 10, 11, 12}));
  EXPECT_EQ(framesOf("7"), (std::vector<long>{7}));
  EXPECT_EQ(framesOf("10-12, 1 - 2"), (std::vector<long>{1, 2, 10, 11, 12})) << "spaced, and sorted";
}

TEST(FrameList, AReversedRangeIsACallersMistakeSayingSo) {
  EXPECT_NE(usageErrorOf("240-1").find("runs backwards"), std::string::npos) << usageErrorOf("240-1");
  EXPECT_NE(usageErrorOf("9:1").find("runs backwards"), std::string::npos);
}

TEST(FrameList, AZeroStepIsACallersMistakeSayingSo) {
  EXPECT_NE(usageErrorOf("1-9x0").find("step"), std::string::npos) << usageErrorOf("1-9x0");
  EXPECT_NE(usageErrorOf("1:9:0").find("step"), std::string::npos);
}

TEST(FrameList, OverlappingItemsAreACallersMistakeNamingBoth) {
  std::string message = usageErrorOf("1-10,5-20");
  EXPECT_NE(message.find("'5-20' overlaps frames 1-10"), std::string::npos) << message;
  EXPECT_NE(usageErrorOf("3,1-4").find("overlaps"), std::string::npos);
}

TEST(FrameList, WordsEmptyItemsAndNegativeFramesAreCallersMistakes) {
  EXPECT_NE(usageErrorOf("lots").find("not a whole number"), std::string::npos);
  EXPECT_NE(usageErrorOf("1,,2").find("empty item"), std::string::npos);
  EXPECT_NE(usageErrorOf("").find("give frames"), std::string::npos);
  EXPECT_NE(usageErrorOf("-1").find("not a whole number"), std::string::npos) << usageErrorOf("-1");
}

TEST(FrameList, FormatsAsAListItReadsBack) {
  for (const char* text : {"1-240x4", "1-6", "1,5,10-20", "3", "1,2", "1001-1240,2000"}) {
    FrameList list = FrameList::parse("--frames", text);
    EXPECT_EQ(FrameList::parse("--frames", list.format()).frames, list.frames) << text << " as " << list.format();
  }
  EXPECT_EQ(FrameList::parse("--frames", "1:9:4").format(":"), "1-9:4");
}

TEST(FramePattern, HashesAndPrintfBothNumberTheFrame) {
  EXPECT_EQ(farm::framePath("shot.####.exr", 42), "shot.0042.exr");
  EXPECT_EQ(farm::framePath("shot.#.png", 1001), "shot.1001.png");
  EXPECT_EQ(farm::framePath("shot.%04d.exr", 42), "shot.0042.exr");
  EXPECT_EQ(farm::framePath("shot_%d.png", 7), "shot_7.png");
}

TEST(FramePattern, SeveralFramesWithoutASlotIsACallersMistake) {
  EXPECT_THROW(farm::checkFramePattern("-o", "shot.exr", 2), std::invalid_argument);
  EXPECT_NO_THROW(farm::checkFramePattern("-o", "shot.exr", 1));
  try {
    farm::checkFramePattern("-o", "shot.exr", 6);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("slot for the frame number"), std::string::npos) << e.what();
  }
}

// A private folder per test, removed after it.
class FarmFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("snell-farm-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void touch(const fs::path& path) const {
    fs::create_directories(path.parent_path());
    std::ofstream(path) << "x";
  }
  CommandRun snell(const std::string& arguments) const {
    return runCommand("cd " + shellQuoted(dir_.string()) + " && " + SNELL_BINARY + " " + arguments);
  }
  fs::path dir_;
};

TEST_F(FarmFolder, SkipExistingRendersOnlyTheFramesWithoutAFile) {
  touch(dir_ / "f_2.png");
  CommandRun run = snell("render --eye --size 16x12 --frames 1-3 --skip-existing -o 'f_#.png'");
  ASSERT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("skipping 1 of 3 frames"), std::string::npos) << run.output;
  EXPECT_EQ(fs::file_size(dir_ / "f_2.png"), 1u) << "the existing frame was rendered again";
  EXPECT_GT(fs::file_size(dir_ / "f_1.png"), 1u);
  EXPECT_GT(fs::file_size(dir_ / "f_3.png"), 1u);
}

TEST_F(FarmFolder, SkipExistingDoesNotTakeAFolderForAFrame) {
  fs::create_directories(dir_ / "f_1.png");
  CommandRun run = snell("render --eye --size 16x12 --frames 1-2 --skip-existing -o 'f_#.png'");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("f_1.png: is a folder"), std::string::npos) << run.output;
}

TEST_F(FarmFolder, StatsJsonRecordsEachFrameWithHashesThatFollowThePixels) {
  CommandRun run = snell("render --eye --size 24x16 --frames 1,48 --method trace -o 'f_#.png' --stats-json 's_#.json'");
  ASSERT_EQ(run.exitCode, 0) << run.output;
  auto read = [&](const char* name) { return nlohmann::json::parse(std::ifstream(dir_ / name)); };
  nlohmann::json first = read("s_1.json"), second = read("s_48.json");
  EXPECT_EQ(first["frame"], 1);
  EXPECT_EQ(first["method"], "trace");
  EXPECT_EQ(first["scene_hash"], second["scene_hash"]);
  EXPECT_NE(first["image_hash"], second["image_hash"]) << "the eye moves between frame 1 and 48";
  EXPECT_TRUE(first["device"].contains("driver")) << first.dump();
  EXPECT_GT(first["frame_ms"].get<double>(), 0.0);
  // The same frame alone, as a retry on another node would render it: the same pixels.
  ASSERT_EQ(snell("render --eye --size 24x16 --frames 48 --method trace -o 'g_#.png' --stats-json 't_#.json'").exitCode, 0);
  EXPECT_EQ(read("t_48.json")["image_hash"], second["image_hash"]);
}

TEST(FarmPlan, CutsTheFramesIntoTasksInOrder) {
  farm::FarmPlan plan = farm::FarmPlan::make("eye.glb", "out/shot.####.exr", FrameList::parse("--frames", "1001-1010"), 4, {});
  ASSERT_EQ(plan.tasks(), 3u);
  EXPECT_EQ(plan.taskFrames(0).frames, (std::vector<long>{1001, 1002, 1003, 1004}));
  EXPECT_EQ(plan.taskFrames(2).frames, (std::vector<long>{1009, 1010}));
  EXPECT_EQ(plan.taskFrames(2).text, "1009,1010");
  EXPECT_TRUE(fs::path(plan.scene).is_absolute());
}

TEST(FarmPlan, NamesItsFolderAfterTheImagesWithoutTheirFrameSlot) {
  farm::FarmPlan plan = farm::FarmPlan::make("eye.glb", "/r/out/shot_%04d.exr", FrameList::parse("--frames", "1-2"), 1, {});
  EXPECT_EQ(plan.name(), "shot");
  EXPECT_EQ(plan.folder(), "/r/out/.snell-farm/shot");
  EXPECT_EQ(plan.statsPattern(), "/r/out/.snell-farm/shot/stats/shot_%04d.json");
}

TEST(FarmPlan, AChunkOfZeroIsACallersMistake) {
  EXPECT_THROW(farm::FarmPlan::make("a.glb", "f_#.png", FrameList::parse("--frames", "1-2"), 0, {}), std::invalid_argument);
}

TEST(FarmPlan, ArrayListsJoinRuns) {
  EXPECT_EQ(farm::arrayList({0, 1, 2, 5, 7, 8}), "0-2,5,7-8");
  EXPECT_EQ(farm::arrayList({3}), "3");
}

TEST_F(FarmFolder, OnlyTasksWithAMissingFrameRunAgain) {
  farm::FarmPlan plan = farm::FarmPlan::make((dir_ / "eye.glb").string(), (dir_ / "f.##.png").string(),
                                           FrameList::parse("--frames", "1-6"), 2, {});
  for (long f : {1, 2, 3, 5, 6}) touch(farm::framePath(plan.output, f));
  EXPECT_EQ(plan.tasksToRun(), (std::vector<size_t>{1}));
  EXPECT_EQ(plan.missingFrames(), (std::vector<long>{4}));
}

TEST_F(FarmFolder, TheCheckNamesMissingFramesAndTheTaskThatFailed) {
  farm::FarmPlan plan = farm::FarmPlan::make((dir_ / "eye.glb").string(), (dir_ / "f.##.png").string(),
                                           FrameList::parse("--frames", "1-6"), 2, {});
  for (long f : {1, 2, 3, 5, 6}) touch(farm::framePath(plan.output, f));
  touch(plan.statusPath("7", 0));
  std::ofstream(plan.statusPath("7", 0)) << "0\n";
  std::ofstream(plan.statusPath("7", 1)) << "1\n";  // task 2 left no status: it did not finish
  farm::FarmCheck check = farm::checkFarm(plan, "7", {0, 1, 2});
  EXPECT_FALSE(check.ok());
  EXPECT_EQ(check.missing, (std::vector<long>{4}));
  ASSERT_EQ(check.failed.size(), 2u);
  EXPECT_NE(check.message.find("missing frames 4"), std::string::npos) << check.message;
  EXPECT_NE(check.message.find("task 1 (frames 3,4) exited 1"), std::string::npos) << check.message;
  EXPECT_NE(check.message.find("task 2 (frames 5,6) did not finish"), std::string::npos) << check.message;
  EXPECT_EQ(check.summary["missing"], nlohmann::ordered_json::array({4}));
  EXPECT_EQ(check.summary["ok"], false);
}

TEST_F(FarmFolder, APlanReadsBackAsWritten) {
  farm::FarmPlan plan = farm::FarmPlan::make("eye.glb", (dir_ / "f.##.png").string(), FrameList::parse("--frames", "1-9x2"),
                                           2, {"--size", "16x12"});
  std::ofstream(dir_ / "plan.json") << plan.toJson().dump();
  farm::FarmPlan back = farm::FarmPlan::read((dir_ / "plan.json").string());
  EXPECT_EQ(back.frames.frames, plan.frames.frames);
  EXPECT_EQ(back.output, plan.output);
  EXPECT_EQ(back.renderOptions, plan.renderOptions);
  std::ofstream(dir_ / "bad.json") << "{\"scene\": 1}";
  EXPECT_THROW(farm::FarmPlan::read((dir_ / "bad.json").string()), std::runtime_error);
}

}  // namespace
}  // namespace snell::test
