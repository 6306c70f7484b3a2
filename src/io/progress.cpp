#include "io/progress.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <unistd.h>

namespace snell::io {

namespace {

// "1 h 02 min", "3 min 05 s", "12.5 s": a duration as people read it.
std::string readableSeconds(double seconds) {
  char text[48];
  if (!(seconds >= 0.0) || !std::isfinite(seconds)) return "?";
  if (seconds < 60.0) {
    std::snprintf(text, sizeof text, "%.1f s", seconds);
  } else if (seconds < 3600.0) {
    std::snprintf(text, sizeof text, "%d min %02d s", int(seconds / 60.0), int(std::fmod(seconds, 60.0)));
  } else {
    std::snprintf(text, sizeof text, "%d h %02d min", int(seconds / 3600.0), int(std::fmod(seconds, 3600.0) / 60.0));
  }
  return text;
}

}  // namespace

Progress::Progress(std::string what, uint64_t total, bool quiet)
    : what_(std::move(what)), total_(total), quiet_(quiet), terminal_(::isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()) {}

void Progress::update(uint64_t done, const std::string& detail) {
  if (quiet_) return;
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  double rate = seconds > 0.0 ? double(done) / seconds : 0.0;
  double left = rate > 0.0 ? double(total_ - std::min(done, total_)) / rate : -1.0;
  std::string timing = done == 0 ? std::string() :
                       done >= total_ ? ", " + readableSeconds(seconds) :
                                        ", " + readableSeconds(left) + " left";
  char rateText[32];
  std::snprintf(rateText, sizeof rateText, "%.2f/s", rate);
  if (terminal_) {
    const int width = 30;
    int filled = total_ ? int(width * std::min(done, total_) / total_) : width;
    std::fprintf(stderr, "\r[%s%s] %llu/%llu %s, %s%s\033[K", std::string(size_t(filled), '#').c_str(),
                 std::string(size_t(width - filled), '.').c_str(), static_cast<unsigned long long>(done),
                 static_cast<unsigned long long>(total_), what_.c_str(), rateText, timing.c_str());
    if (done >= total_) std::fputc('\n', stderr);
  } else {
    std::fprintf(stderr, "%llu/%llu %s%s%s, %s%s\n", static_cast<unsigned long long>(done),
                 static_cast<unsigned long long>(total_), what_.c_str(), detail.empty() ? "" : ": ", detail.c_str(),
                 rateText, timing.c_str());
  }
  std::fflush(stderr);
}

}  // namespace snell::io
