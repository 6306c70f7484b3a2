// Every pipeline the renderer can choose on a device, as the passes describe
// them (each pass's programDesc(s), the same ones its constructor makes), for
// `snell bench pipelines`: compiling them needs no device memory, so the
// driver's statistics (registers, spills, instructions) can be read on a
// machine without the GPU, through a null device such as RADV's.
#pragma once

#include "vk/compute_program.h"
#include "vk/context.h"
#include "vk/graphics_program.h"
#include "vk/ray_tracing_program.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace snell::render {

/// One pipeline: exactly one of the three descriptions is set.
struct CataloguedPipeline {
  std::string pass;     ///< "trace", "bvh", "sort", "raster", "driver-rt", ...
  std::string variant;  ///< which of the pass's pipelines, in words ("masked, 4 lanes a pixel, surface 0x21")
  std::optional<vk::ComputeProgramDesc> compute;
  std::optional<vk::GraphicsProgramDesc> graphics;
  std::optional<vk::RayTracingProgramDesc> rayTracing;
  /// The trace's specialisation (pass "trace" only): gpu::kOptics*, gpu::kTraceFlag*, lanes a pixel, gpu::kSurface*.
  uint32_t optics = 0, flags = 0, lanes = 0, surface = 0;
};

/// The trace's specialisations a renderer chooses among, by what a scene and
/// a view ask for: each surface feature (textures with each kind of map,
/// alpha, single-sided faces) and all of them, the AOVs and a ray list, the
/// masked viewport at 1, 2, 4 and 8 lanes a pixel (as the device's smallest
/// subgroup allows), and every optics feature at once.
std::vector<CataloguedPipeline> traceCatalogue(const vk::Context& context);

/// Every pipeline: the trace's (traceCatalogue), then the trace's compaction,
/// the tree builds and refits, the sorts and scans, deform, refine, texture
/// mips, the raster's and, where the device offers ray tracing pipelines, driver-rt's.
std::vector<CataloguedPipeline> pipelineCatalogue(const vk::Context& context);

}  // namespace snell::render
