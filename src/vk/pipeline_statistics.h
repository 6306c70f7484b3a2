// What a driver says about a compiled pipeline (VK_KHR_pipeline_executable_properties):
// for each executable (a shader stage, as the driver compiled it) its registers,
// spills, code size, instructions and whatever else the driver counts.
#pragma once

#include <vulkan/vulkan.h>

#include <string>
#include <vector>

namespace snell::vk {

class Context;

/// One statistic of one executable of a pipeline.
struct PipelineStatistic {
  std::string executable;  ///< the driver's name for the executable ("Compute Shader", "Vertex Shader", ...)
  std::string name;        ///< the driver's name for the statistic ("VGPRs", "Register Count", ...)
  double value = 0.0;      ///< booleans as 0 or 1
};

/// The driver's statistics of `pipeline`, made with
/// VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR; empty unless the context
/// captures statistics (Context::caps().pipelineStatistics).
std::vector<PipelineStatistic> pipelineStatistics(const Context& context, VkPipeline pipeline);

/// "name = value" lines of `statistics`, each prefixed by its executable's
/// name where the pipeline has several.
std::vector<std::string> statisticLines(const std::vector<PipelineStatistic>& statistics);

}  // namespace snell::vk
