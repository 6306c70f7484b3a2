// `snell bench pipelines`: every pipeline compiles for AMD without AMD
// hardware (RADV's null device, through Mesa's ACO), at both of AMD's
// subgroup widths, and the trace's registers are held to the committed
// baselines; a null device is a clear error for everything that would run.
#include "command_run.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <string>

namespace snell::test {
namespace {

const std::string kRadvNullDevice =
    "RADV_FORCE_FAMILY=gfx1100 VK_DRIVER_FILES=/usr/share/vulkan/icd.d/radeon_icd.x86_64.json ";

std::string baseline(const std::string& family) {
  return shellQuoted(std::string(SNELL_SOURCE_DIR) + "/bench/results/pipelines-radv-" + family + ".json");
}

// Every pipeline compiled and none failed: the summary line says so.
void expectEveryPipelineCompiled(const CommandRun& run) {
  ASSERT_EQ(run.exitCode, 0) << run.output;
  std::smatch counts;
  ASSERT_TRUE(std::regex_search(run.output, counts, std::regex("(\\d+) pipelines compiled in [0-9.]+ s, (\\d+) failed")))
      << run.output;
  EXPECT_GE(std::stoi(counts[1]), 35) << "fewer pipelines than the renderer has:\n" << run.output;
  EXPECT_EQ(counts[2], "0") << run.output;
  // The pipelines that spill, named in the test's log whether it passes or not.
  std::smatch spill;
  for (std::string rest = run.output; std::regex_search(rest, spill, std::regex("  spills: [^\n]*")); rest = spill.suffix()) {
    std::cout << spill[0] << "\n";
  }
}

// Wave64, RADV's default, with the guard: on RDNA3 Mesa 22.3's compiler holds
// the trace near 128 VGPRs and spills the rest, so a rise shows in spills;
// on RDNA2 it shows in VGPRs (bench/results/pipelines-radv-history.md).
TEST(AmdPipelines, EveryPipelineCompilesForRdna3InWave64WithinTheTracesRegisterBaseline) {
  CommandRun run = snell("bench pipelines --amd gfx1100 --baseline " + baseline("gfx1100"));
  expectEveryPipelineCompiled(run);
  EXPECT_NE(run.output.find("every trace pipeline within"), std::string::npos) << run.output;
}

TEST(AmdPipelines, EveryPipelineCompilesForRdna2InWave64WithinTheTracesRegisterBaseline) {
  CommandRun run = snell("bench pipelines --amd gfx1030 --baseline " + baseline("gfx1030"));
  expectEveryPipelineCompiled(run);
  EXPECT_NE(run.output.find("NAVI21"), std::string::npos) << "not RDNA2's compiler:\n" << run.output;
  EXPECT_NE(run.output.find("every trace pipeline within"), std::string::npos) << run.output;
}

TEST(AmdPipelines, EveryPipelineCompilesForRdna3InWave32) {
  CommandRun run = snell("bench pipelines --amd gfx1100 --subgroup-size 32");
  expectEveryPipelineCompiled(run);
  EXPECT_NE(run.output.find("compiled for subgroups of 32 lanes"), std::string::npos) << run.output;
}

TEST(AmdPipelines, EveryPipelineCompilesForRdna2InWave32) {
  expectEveryPipelineCompiled(snell("bench pipelines --amd gfx1030 --subgroup-size 32"));
}

// A baseline that records fewer registers than the trace holds: the guard
// fails, naming the pipeline and both counts.
TEST(AmdPipelines, ARegisterRiseFailsNamingThePipelineAndBothCounts) {
  std::ifstream in(std::string(SNELL_SOURCE_DIR) + "/bench/results/pipelines-radv-gfx1030.json");
  nlohmann::ordered_json j = nlohmann::ordered_json::parse(in);
  bool lowered = false;
  double was = 0;
  for (auto& p : j["pipelines"]) {
    if (p["variant"] != "full frame, surface 0x21") continue;
    auto& stats = p["executables"][0]["statistics"];
    was = stats["VGPRs"].get<double>();
    stats["VGPRs"] = was - 8;
    lowered = true;
  }
  ASSERT_TRUE(lowered) << "the baseline has no 'full frame, surface 0x21' trace pipeline";
  std::filesystem::path file = std::filesystem::temp_directory_path() / "snell-lowered-baseline.json";
  std::ofstream(file) << j.dump(2);
  CommandRun run =
      snell("bench pipelines --amd gfx1030 --only 'full frame, surface 0x21' --baseline " + shellQuoted(file.string()));
  std::filesystem::remove(file);
  EXPECT_EQ(run.exitCode, 1) << run.output;
  std::string expected = "trace: full frame, surface 0x21: " + std::to_string(int(was)) + " VGPRs, up from " +
                         std::to_string(int(was - 8));
  EXPECT_NE(run.output.find(expected), std::string::npos) << "expected '" << expected << "' in:\n" << run.output;
}

TEST(Pipelines, ADriverWithoutStatisticsSaysSoAndStillCompilesEachPipeline) {
  CommandRun run = snell("bench pipelines --only compaction");  // lavapipe, or whichever device runs the tests
  ASSERT_EQ(run.exitCode, 0) << run.output;
  if (run.output.find("llvmpipe") == std::string::npos) GTEST_SKIP() << "not lavapipe:\n" << run.output;
  EXPECT_NE(run.output.find("reports no pipeline statistics"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("1 pipelines compiled"), std::string::npos) << run.output;
}

TEST(Pipelines, ANullDeviceIsAClearErrorForAnythingThatRuns) {
  CommandRun run = runCommand(kRadvNullDevice + std::string(SNELL_BINARY) + " render --eye --size 32x24 -o " +
                              shellQuoted((std::filesystem::temp_directory_path() / "snell-null.png").string()));
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("no device-local memory"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("snell bench pipelines"), std::string::npos) << "the error names what the device is for:\n"
                                                                        << run.output;
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::temp_directory_path() / "snell-null.png"));
}

}  // namespace
}  // namespace snell::test
