// Makes one header readable as both GLSL and C++: under C++ the GLSL scalar and
// vector names alias GLM types, so a struct declared once has one layout everywhere.
#ifndef SNELL_SHARED_TYPES_H
#define SNELL_SHARED_TYPES_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace snell::gpu {
using uint = std::uint32_t;
using uvec2 = glm::uvec2;
using uvec4 = glm::uvec4;
using vec4 = glm::vec4;
}  // namespace snell::gpu
#define SNELL_GPU_BEGIN namespace snell::gpu {
#define SNELL_GPU_END }
#define SNELL_CONST inline constexpr uint
#else
#define SNELL_GPU_BEGIN
#define SNELL_GPU_END
#define SNELL_CONST const uint
#endif

#endif
