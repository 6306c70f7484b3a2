// One JSON writer for every machine-readable output (`--json` of info, the
// benchmarks, snell-view): nlohmann's, so names with quotes, backslashes or any
// UTF-8 come out as valid JSON. Each file opens with the same head
// (docs/json.md) so results from different machines can be compared.
#pragma once

#include "vk/device_selection.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace snell::io {

/// Keys keep the order they were written in, so files read top-down like the tables.
using Json = nlohmann::ordered_json;

/// Remembers the process's command line for every head; main() calls it once.
void recordCommandLine(int argc, const char* const* argv);
/// The command line as recorded, words joined by spaces (quoted where needed).
std::string commandLine();
/// A word as a POSIX shell reads it back as one word: as it is, or in single quotes.
std::string shellQuoted(const std::string& word);

/// The device and its driver, as every head carries them.
Json deviceJson(const vk::DeviceFacts& device);

/// The head of a `kind` file: {"schema": "snell.KIND/1", "snell_version",
/// "created" (UTC, ISO 8601), "command_line", "device" (when given)}; the
/// caller adds its own fields after it.
Json reportHead(const std::string& kind, const vk::DeviceFacts* device);

/// `json` as text: two-space indents, invalid UTF-8 replaced rather than thrown.
std::string jsonText(const Json& json);

/// Writes `json` to `path`, complete or not at all (as writeTextFile).
void writeJson(const std::string& path, const Json& json);

/// The median of `values` (0 when empty): what every report and table quotes.
double median(std::vector<double> values);

}  // namespace snell::io
