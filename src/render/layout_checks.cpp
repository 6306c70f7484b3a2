// Every struct in shaders/shared/ is read by GLSL with std430 rules; these
// checks fail the build if the C++ view of a layout drifts from the budget its
// header states.
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

}  // namespace snell::gpu
