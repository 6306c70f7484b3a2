// Every struct in shaders/shared/ is read by GLSL with std430 rules; these
// checks fail the build if the C++ view of a layout drifts from the budget its
// header states.
#include "shared/deform.h"
#include "shared/prefix_sum.h"
#include "shared/radix_sort.h"

#include <cstddef>

namespace snell::gpu {

static_assert(sizeof(ScanPush) == 16);
static_assert(offsetof(ScanPush, count) == 0);
static_assert(offsetof(ScanPush, blockCount) == 4);
static_assert(offsetof(ScanPush, addPartials) == 8);

static_assert(sizeof(SortPush) == 16);
static_assert(offsetof(SortPush, count) == 0);
static_assert(offsetof(SortPush, blockCount) == 4);
static_assert(offsetof(SortPush, shift) == 8);
static_assert(kSortRadix == 1u << kSortRadixBits);

static_assert(sizeof(DeformPush) == 16);
static_assert(offsetof(DeformPush, vertexCount) == 0);
static_assert(offsetof(DeformPush, targetCount) == 4);
static_assert(offsetof(DeformPush, jointCount) == 8);
// deform.comp reads these as std430 uvec4[], vec4[] and mat4[].
static_assert(sizeof(glm::uvec4) == 16 && sizeof(glm::vec4) == 16 && sizeof(glm::mat4) == 64);

}  // namespace snell::gpu
