// The command line's option parsing: NUL-separated words, the first naming
// the subcommand. A bad command line is a UsageError (exit 2 in `snell`);
// nothing else may escape, and nothing runs (the parsers touch no file).
#include "fuzz_input.h"

#include "cli/cli.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> words = snell::fuzz::splitArguments(data, size);
  snell::cli::Args args(words.begin() + 1, words.end());
  try {
    if (words[0] == "render") snell::cli::parseRenderOptions(args);
    else if (words[0] == "bake") snell::cli::parseBakeOptions(args);
    else if (words[0] == "export-web") snell::cli::parseExportWebOptions(args);
  } catch (const snell::cli::UsageError&) {
  }
  return 0;
}
