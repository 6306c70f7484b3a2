#include "io/environment.h"

#include <cstdio>
#include <cstdlib>
#include <string>

#include <unistd.h>

namespace snell::io {

vk::ContextDesc contextDescFromEnvironment() {
  vk::ContextDesc desc;
  const char* validation = std::getenv("SNELL_VALIDATION");
  desc.validation = validation && std::string(validation) == "1";
  desc.synchronizationValidation = desc.validation;  // as the tests' own context has it
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
