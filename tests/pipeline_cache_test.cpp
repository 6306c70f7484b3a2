// The pipeline cache on disk: written when a context ends, loaded by the next,
// and never an error when the file is bad or cannot be written.
#include "assets.h"

#include "vk/compute_program.h"
#include "vk/context.h"
#include "vk/pipeline_cache.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "fill_index.spv.h"

namespace snell::test {
namespace {

namespace fs = std::filesystem;

// SNELL_PIPELINE_CACHE for one test (each test runs in its own process).
struct CacheFolder {
  explicit CacheFolder(const std::string& value) { ::setenv("SNELL_PIPELINE_CACHE", value.c_str(), 1); }
  ~CacheFolder() { ::unsetenv("SNELL_PIPELINE_CACHE"); }
};

std::unique_ptr<vk::Context> contextWithAPipeline() {
  std::unique_ptr<vk::Context> context = vk::Context::create();
  vk::ComputeProgram program(*context, {"fill index", kSpvFillIndex, {}, false});
  return context;
}

TEST(PipelineCache, AContextWritesItsCacheAndTheNextOneLoadsIt) {
  fs::path dir = scratchDir("pipeline-cache");
  CacheFolder folder(dir.string());
  fs::path file;
  {
    auto context = contextWithAPipeline();
    ASSERT_TRUE(context->diskCache());
    file = context->diskCache()->path();
    EXPECT_EQ(file.parent_path(), dir);
    EXPECT_EQ(context->diskCache()->loadedBytes(), 0u);
    EXPECT_GE(context->pipelinesCreated(), 1u);
  }
  ASSERT_TRUE(fs::exists(file)) << file;
  EXPECT_GE(fs::file_size(file), 32u) << "at least the header";
  auto next = vk::Context::create();
  EXPECT_EQ(next->diskCache()->loadedBytes(), fs::file_size(file));
  EXPECT_TRUE(next->diskCache()->warning().empty()) << next->diskCache()->warning();
}

TEST(PipelineCache, AFileOfAnotherDeviceOrGarbageIsIgnoredWithANote) {
  fs::path dir = scratchDir("pipeline-cache-corrupt");
  CacheFolder folder(dir.string());
  fs::path file = vk::Context::create()->diskCache()->path();
  std::ofstream(file, std::ios::binary | std::ios::trunc) << std::string(200, 'x');
  auto context = contextWithAPipeline();
  EXPECT_EQ(context->diskCache()->loadedBytes(), 0u);
  EXPECT_NE(context->diskCache()->warning().find("ignored the pipeline cache"), std::string::npos)
      << context->diskCache()->warning();
}

TEST(PipelineCache, AFolderThatCannotBeWrittenIsANoteNotAnError) {
  CacheFolder folder("/proc/snell-cannot-write-here");
  auto context = contextWithAPipeline();
  vk::PipelineCache& cache = const_cast<vk::PipelineCache&>(*context->diskCache());
  std::string failed = cache.save();
  EXPECT_NE(failed.find("could not write the pipeline cache"), std::string::npos) << failed;
}

TEST(PipelineCache, OffKeepsNothingOnDisk) {
  CacheFolder folder("off");
  auto context = contextWithAPipeline();
  EXPECT_TRUE(context->diskCache()->path().empty());
  EXPECT_EQ(const_cast<vk::PipelineCache&>(*context->diskCache()).save(), "");
}

TEST(PipelineCache, TheFileIsNamedByTheDevicesCacheUuidAndDriver) {
  VkPhysicalDeviceProperties properties{};
  properties.vendorID = 0x10de;
  properties.deviceID = 0x2330;
  properties.driverVersion = 0x91000000;
  properties.pipelineCacheUUID[0] = 0xab;
  CacheFolder folder("/tmp/snell-cache-name");
  fs::path path = vk::PipelineCache::pathFor(properties);
  EXPECT_EQ(path.parent_path(), "/tmp/snell-cache-name");
  EXPECT_EQ(path.filename().string(), "pipelines-10de-2330-91000000-ab000000000000000000000000000000.bin");
}

TEST(PipelineCache, WithoutTheVariableItLivesInTheXdgCacheFolder) {
  ::unsetenv("SNELL_PIPELINE_CACHE");
  ::setenv("XDG_CACHE_HOME", "/tmp/snell-xdg-cache", 1);
  fs::path path = vk::PipelineCache::pathFor(VkPhysicalDeviceProperties{});
  EXPECT_EQ(path.parent_path(), "/tmp/snell-xdg-cache/snell");
}

}  // namespace
}  // namespace snell::test
