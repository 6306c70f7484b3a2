// What the process's environment says about the GPU work: which device, whether
// the validation layer watches. Shared by `snell`, `snell-view` and the tests.
#pragma once

#include "vk/context.h"

#include <cstdint>

namespace snell::io {

/// A context on the device snell picks (SNELL_DEVICE, or --device, which sets
/// it); SNELL_VALIDATION=1 turns on the validation layer, synchronization
/// checks included.
vk::ContextDesc contextDescFromEnvironment();

/// This process's resident host memory in bytes (/proc/self/statm), for the
/// long runs' reports.
uint64_t hostResidentBytes();

}  // namespace snell::io
