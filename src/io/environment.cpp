#include "io/environment.h"

#include <cstdio>
#include <cstdlib>
#include <string>

#include <unistd.h>

namespace snell::io {

vk::DeviceEnvironment deviceEnvironment() {
  vk::DeviceEnvironment environment;
  if (const char* device = std::getenv("SNELL_DEVICE"); device && *device) environment.device = device;
  for (const char* variable : {"CUDA_VISIBLE_DEVICES", "GPU_DEVICE_ORDINAL", "SLURM_STEP_GPUS", "SLURM_JOB_GPUS"}) {
    const char* value = std::getenv(variable);
    if (!value || !*value || *value == '-' || std::string(value) == "NoDevFiles") continue;
    environment.launcherVariable = variable;
    environment.launcherValue = value;
    break;
  }
  return environment;
}

void keepToTheTasksCpus() {
  const char* cpus = std::getenv("SLURM_CPUS_PER_TASK");
  if (cpus && *cpus && !std::getenv("LP_NUM_THREADS")) ::setenv("LP_NUM_THREADS", cpus, 0);
}

vk::ContextDesc contextDescFromEnvironment() {
  vk::ContextDesc desc;
  desc.environment = deviceEnvironment();
  const char* validation = std::getenv("SNELL_VALIDATION");
  desc.validation = validation && std::string(validation) == "1";
  desc.synchronizationValidation = desc.validation;  // as the tests' own context has it
  desc.robustBufferAccess = desc.validation;
  return desc;
}

uint64_t hostResidentBytes() {
  std::FILE* statm = std::fopen("/proc/self/statm", "r");
  if (!statm) return 0;
  unsigned long long size = 0, resident = 0;
  int read = std::fscanf(statm, "%llu %llu", &size, &resident);
  std::fclose(statm);
  return read == 2 ? uint64_t(resident) * uint64_t(::sysconf(_SC_PAGESIZE)) : 0;
}

}  // namespace snell::io
