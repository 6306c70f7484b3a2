// What the process's environment says about the GPU work, read here and
// nowhere else: which device (SNELL_DEVICE, or the GPUs a launcher such as
// Slurm gave the process), whether the validation layer watches, and how
// many CPUs lavapipe may take. Shared by `snell`, `snell-view`, libsnell and the tests.
#pragma once

#include "vk/context.h"

#include <cstdint>

namespace snell::io {

/// SNELL_DEVICE, else the first of CUDA_VISIBLE_DEVICES, GPU_DEVICE_ORDINAL,
/// SLURM_STEP_GPUS and SLURM_JOB_GPUS that lists a GPU (unset, empty, "-1"
/// or Slurm's "NoDevFiles" list none). Slurm's own lists come last: its GPU
/// plugin sets CUDA_VISIBLE_DEVICES beside them wherever it hands out GPUs.
vk::DeviceEnvironment deviceEnvironment();

/// A context on the device the environment picks (deviceEnvironment, or
/// --device, which sets SNELL_DEVICE); SNELL_VALIDATION=1 turns on the
/// validation layer, synchronization checks included.
vk::ContextDesc contextDescFromEnvironment();

/// lavapipe starts a thread per CPU of the node; a Slurm task given N CPUs
/// (SLURM_CPUS_PER_TASK) keeps to N, unless LP_NUM_THREADS says otherwise.
void keepToTheTasksCpus();

/// This process's resident host memory in bytes (/proc/self/statm), for the
/// long runs' reports.
uint64_t hostResidentBytes();

}  // namespace snell::io
