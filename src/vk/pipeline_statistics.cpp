// Reading a pipeline's statistics from the driver (see pipeline_statistics.h).
#include "vk/pipeline_statistics.h"

#include "vk/context.h"
#include "vk/error.h"

#include <cstdio>
#include <set>

namespace snell::vk {

std::vector<PipelineStatistic> pipelineStatistics(const Context& context, VkPipeline pipeline) {
  std::vector<PipelineStatistic> statistics;
  if (!context.caps().pipelineStatistics || pipeline == VK_NULL_HANDLE) return statistics;
  VkDevice device = context.device();
  auto getProperties = reinterpret_cast<PFN_vkGetPipelineExecutablePropertiesKHR>(
      vkGetDeviceProcAddr(device, "vkGetPipelineExecutablePropertiesKHR"));
  auto getStatistics = reinterpret_cast<PFN_vkGetPipelineExecutableStatisticsKHR>(
      vkGetDeviceProcAddr(device, "vkGetPipelineExecutableStatisticsKHR"));
  if (!getProperties || !getStatistics) return statistics;
  VkPipelineInfoKHR pipelineInfo{VK_STRUCTURE_TYPE_PIPELINE_INFO_KHR};
  pipelineInfo.pipeline = pipeline;
  uint32_t executables = 0;
  VK_CHECK(getProperties(device, &pipelineInfo, &executables, nullptr));
  std::vector<VkPipelineExecutablePropertiesKHR> properties(executables,
                                                            {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_PROPERTIES_KHR});
  VK_CHECK(getProperties(device, &pipelineInfo, &executables, properties.data()));
  for (uint32_t e = 0; e < executables; ++e) {
    VkPipelineExecutableInfoKHR executable{VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR};
    executable.pipeline = pipeline;
    executable.executableIndex = e;
    uint32_t count = 0;
    VK_CHECK(getStatistics(device, &executable, &count, nullptr));
    std::vector<VkPipelineExecutableStatisticKHR> stats(count, {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR});
    VK_CHECK(getStatistics(device, &executable, &count, stats.data()));
    for (const VkPipelineExecutableStatisticKHR& s : stats) {
      PipelineStatistic statistic{properties[e].name, s.name, 0.0};
      switch (s.format) {
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR: statistic.value = s.value.b32 ? 1.0 : 0.0; break;
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR: statistic.value = double(s.value.i64); break;
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR: statistic.value = double(s.value.u64); break;
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_FLOAT64_KHR: statistic.value = s.value.f64; break;
        default: continue;
      }
      statistics.push_back(std::move(statistic));
    }
  }
  return statistics;
}

std::vector<std::string> statisticLines(const std::vector<PipelineStatistic>& statistics) {
  std::set<std::string> executables;
  for (const PipelineStatistic& s : statistics) executables.insert(s.executable);
  std::vector<std::string> lines;
  for (const PipelineStatistic& s : statistics) {
    char value[32];
    std::snprintf(value, sizeof value, "%.15g", s.value);
    lines.push_back((executables.size() > 1 ? s.executable + ": " : std::string()) + s.name + " = " + value);
  }
  return lines;
}

}  // namespace snell::vk
