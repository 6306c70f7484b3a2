// Progress of long work (frames rendered, scenes measured) on standard error:
// a bar redrawn in place with the rate and the time left when standard error is
// a terminal; one plain line per step when it goes to a file or a pipe, so logs
// hold no carriage returns; nothing at all when quiet.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace snell::io {

class Progress {
 public:
  /// `what` names the steps ("frames"); `total` of them are expected.
  Progress(std::string what, uint64_t total, bool quiet);
  /// `done` steps are complete; `detail` (a file written) goes on a redirected line.
  void update(uint64_t done, const std::string& detail = {});
  /// Whether this goes to a terminal (the bar) or a log (lines).
  bool terminal() const { return terminal_; }

 private:
  std::string what_;
  uint64_t total_;
  bool quiet_, terminal_;
  std::chrono::steady_clock::time_point start_;
};

/// "1 h 02 min", "3 min 05 s", "12.5 s": a duration as people read it.
std::string readableSeconds(double seconds);

}  // namespace snell::io
