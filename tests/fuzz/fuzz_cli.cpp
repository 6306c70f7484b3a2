// The command line's option parsing: NUL-separated words, as `snell` gets
// them after its name. A bad command line is a UsageError (exit 2 in
// `snell`); nothing else may escape, and nothing runs: parsing only sets what
// would run.
#include "fuzz_input.h"

#include "cli/commands.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> words = snell::fuzz::splitArguments(data, size);
  snell::cli::Runner run;
  std::unique_ptr<CLI::App> app = snell::cli::makeSnellApp(run);
  try {
    snell::cli::parseOnly(*app, words);
  } catch (const snell::cli::UsageError&) {
  }
  return 0;
}
