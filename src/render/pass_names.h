// The names of a frame's timed passes (vk::PassTime::name, the JSON reports'
// "passes"): the passes begin under these names and the benchmarks and the
// auto method find them by the same constants, so a renamed pass cannot
// silently drop out of a table. The driver-rt peer's are in peer/pass_names.h.
#pragma once

#include "peer/pass_names.h"

namespace snell::pass {

inline constexpr const char* kDeform = "deform";
inline constexpr const char* kRefine = "refine";
inline constexpr const char* kBlasBuild = "blas build";
inline constexpr const char* kBlasRefit = "blas refit";
inline constexpr const char* kTlas = "tlas";
inline constexpr const char* kSortHistogram = "histogram";
inline constexpr const char* kSortScan = "scan";
inline constexpr const char* kSortScatter = "scatter";
// The build's steps, with BvhBuilder::setStepTiming (bench scale's breakdown).
inline constexpr const char* kBvhBoxes = "bvh boxes";
inline constexpr const char* kBvhMorton = "bvh morton";
inline constexpr const char* kBvhSort = "bvh sort";
inline constexpr const char* kBvhHploc = "bvh hploc";  // with any restructuring rounds
inline constexpr const char* kBvhQuantise = "bvh quantise";
inline constexpr const char* kTraceList = "trace list";
inline constexpr const char* kTrace = "trace";
inline constexpr const char* kRasterDepth = "raster depth";
inline constexpr const char* kRasterShading = "raster shading";

}  // namespace snell::pass
