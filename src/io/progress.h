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

 private:
  std::string what_;
  uint64_t total_;
  bool quiet_, terminal_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace snell::io
