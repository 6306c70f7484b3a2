// `snell render --devices`: a shot's frames over several devices, a worker
// each, taking frames from one queue. On lavapipe, two workers share the one
// device (--devices 0,0: two logical devices), which is enough to hold the
// queue to its word: every frame written once, the pixels one worker writes,
// and a device lost mid-shot handing its frames to the other.
#include "command_run.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>

namespace snell::test {
namespace {

namespace fs = std::filesystem;

class MultiDevice : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("snell-multi-device-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Renders 12 frames of the eye into NAME_#.png with a record each in NAME_#.json.
  CommandRun render(const std::string& name, const std::string& extra, const std::string& environment = "") const {
    return runCommand("cd " + shellQuoted(dir_.string()) + " && " + environment + " " + SNELL_BINARY +
                      " render --eye --size 64x48 --frames 1-12 --fps 6 --method trace -o '" + name +
                      "_#.png' --stats-json '" + name + "_#.json' " + extra);
  }
  // Each frame's pixel hash, and which worker wrote it.
  std::map<long, std::pair<std::string, int>> records(const std::string& name) const {
    std::map<long, std::pair<std::string, int>> out;
    for (long f = 1; f <= 12; ++f) {
      std::ifstream in(dir_ / (name + "_" + std::to_string(f) + ".json"));
      if (!in) continue;
      nlohmann::json j = nlohmann::json::parse(in);
      out[f] = {j["image_hash"], j.value("worker", -1)};
    }
    return out;
  }
  size_t images(const std::string& name) const {
    size_t count = 0;
    for (const auto& entry : fs::directory_iterator(dir_)) {
      std::string file = entry.path().filename().string();
      count += file.rfind(name + "_", 0) == 0 && entry.path().extension() == ".png";
    }
    return count;
  }
  fs::path dir_;
};

TEST_F(MultiDevice, TwoWorkersWriteEveryFrameOnceWithOneWorkersPixels) {
  ASSERT_EQ(render("one", "").exitCode, 0);
  CommandRun two = render("two", "--devices 0,0");
  ASSERT_EQ(two.exitCode, 0) << two.output;
  EXPECT_NE(two.output.find("12 frames on 2 devices"), std::string::npos) << two.output;
  auto one = records("one"), both = records("two");
  ASSERT_EQ(both.size(), 12u);
  EXPECT_EQ(images("two"), 12u);
  std::map<int, int> byWorker;
  for (long f = 1; f <= 12; ++f) {
    EXPECT_EQ(both[f].first, one[f].first) << "frame " << f << " differs from one worker's";
    ++byWorker[both[f].second];
  }
  EXPECT_EQ(byWorker.size(), 2u) << "both workers should have taken frames";
}

TEST_F(MultiDevice, ADeviceLostMidShotHandsItsFramesToTheOther) {
  ASSERT_EQ(render("one", "").exitCode, 0);
  // Worker 1's 20th queue submission fails (a few frames in) and every later one.
  CommandRun run = render("lost", "--devices 0,0", "SNELL_FAULT=vkQueueSubmit:VK_ERROR_DEVICE_LOST:20 SNELL_FAULT_WORKER=1");
  ASSERT_EQ(run.exitCode, 0) << "every frame was written anyway: " << run.output;
  EXPECT_NE(run.output.find("worker 1 lost its device"), std::string::npos) << run.output;
  auto one = records("one"), lost = records("lost");
  ASSERT_EQ(lost.size(), 12u);
  EXPECT_EQ(images("lost"), 12u) << "no frame twice, none half-written";
  int byWorker1 = 0;
  for (long f = 1; f <= 12; ++f) {
    EXPECT_EQ(lost[f].first, one[f].first) << "frame " << f;
    byWorker1 += lost[f].second == 1;
  }
  EXPECT_LT(byWorker1, 6) << "worker 1 stopped early; worker 0 took the rest";
}

TEST_F(MultiDevice, EveryDeviceLostEndsWithExitThreeAndOnlyWholeFrames) {
  CommandRun run = render("all", "--devices 0,0", "SNELL_FAULT=vkQueueSubmit:VK_ERROR_DEVICE_LOST:40");
  EXPECT_EQ(run.exitCode, 3) << run.output;
  EXPECT_NE(run.output.find("VK_ERROR_DEVICE_LOST"), std::string::npos) << run.output;
  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_TRUE(entry.path().extension() == ".png" || entry.path().extension() == ".json") << entry.path();
  }
}

TEST_F(MultiDevice, ADeviceListThatNamesNoDeviceIsAnErrorNamingTheEntry) {
  CommandRun run = render("x", "--devices 0,9");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("--devices 0,9: no device 9"), std::string::npos) << run.output;
  EXPECT_EQ(images("x"), 0u);
}

TEST_F(MultiDevice, AMalformedDeviceListIsAUsageError) {
  for (const char* list : {"0,,1", ",0", "0,"}) {
    CommandRun run = render("x", std::string("--devices ") + list);
    EXPECT_EQ(run.exitCode, 2) << list << ": " << run.output;
    EXPECT_NE(run.output.find("give all, or device indices and UUIDs"), std::string::npos) << run.output;
  }
  CommandRun reference = runCommand(std::string(SNELL_BINARY) + " render --eye --reference --devices all -o /tmp/x.png");
  EXPECT_EQ(reference.exitCode, 2) << reference.output;
}

}  // namespace
}  // namespace snell::test
