// The names the driver-rt peer's timed passes begin under (vk::PassTime::name).
// render/pass_names.h adds snell's own; the benchmarks find both by these
// constants, so a renamed pass cannot silently drop out of a table.
#pragma once

namespace snell::pass {

inline constexpr const char* kDriverBlasBuild = "driver blas build";
inline constexpr const char* kDriverBlasUpdate = "driver blas update";
inline constexpr const char* kDriverTlas = "driver tlas";
inline constexpr const char* kDriverTrace = "driver trace";

}  // namespace snell::pass
