// Other programs: run to the end with what they print collected (a farm's
// sbatch and sinfo), found on PATH, and this program's own path.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace snell::io {

struct ProcessResult {
  int exitCode = 0;  ///< the program's, or 128 + the signal that ended it
  std::string out, err;
};

/// Runs `argv` (no shell) to its end, collecting what it prints; `tick`
/// runs about once a second meanwhile (progress while `sbatch --wait`
/// waits). Throws std::runtime_error naming the program when it cannot start.
ProcessResult runProcess(const std::vector<std::string>& argv, const std::function<void()>& tick = {});
/// Whether `program` is an executable on PATH.
bool onPath(const std::string& program);
/// The running program's own file (/proc/self/exe), so that jobs it writes
/// run the same build on every node; `fallback` where it cannot be read.
std::string thisExecutable(const std::string& fallback);
/// `text` without the white space at its ends.
std::string trimmed(std::string text);

}  // namespace snell::io
