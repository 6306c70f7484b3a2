// The `snell` command's subcommands; main.cpp routes to them.
#pragma once

#include "vk/context.h"

#include <cstdint>
#include <string>
#include <vector>

namespace snell::cli {

/// The words after the subcommand's name.
using Args = std::vector<std::string>;

/// Thrown for a bad command line; main prints it with the usage hint, exit 2.
struct UsageError {
  std::string message;
};

int runInfo(const Args& args);
int runBenchSort(const Args& args);
int runEye(const Args& args);
int runRender(const Args& args);
int runBenchBvh(const Args& args);
int runBenchFrame(const Args& args);
int runBenchStress(const Args& args);
int runBenchScale(const Args& args);
int runBenchMethods(const Args& args);

/// A context on the device snell picks; SNELL_VALIDATION=1 turns on the
/// validation layer, synchronization checks included.
vk::ContextDesc contextDescFromEnvironment();

/// Parses WxH (each 1..65536) or throws UsageError naming the option.
void parseSize(const std::string& option, const std::string& value, uint32_t& width, uint32_t& height);

/// Parses an unsigned integer option value or throws UsageError naming the option.
unsigned long long parseCount(const std::string& option, const std::string& value);

/// Parses a texture budget in MiB (1..2^20) into bytes, or throws UsageError naming the option.
uint64_t parseTextureBudget(const std::string& option, const std::string& value);

/// The median of `values` (0 when empty), for benchmark tables.
double median(std::vector<double> values);

/// `text` as the inside of a JSON string.
std::string jsonEscape(const std::string& text);

}  // namespace snell::cli
