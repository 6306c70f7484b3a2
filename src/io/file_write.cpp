#include "io/file_write.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <unistd.h>

namespace snell::io {

namespace fs = std::filesystem;

uint8_t linearToSrgb8(float linear) {
  float c = std::clamp(std::isnan(linear) ? 0.0f : linear, 0.0f, 1.0f);
  float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return static_cast<uint8_t>(std::lround(s * 255.0f));
}

fs::path existingFolder(const std::string& path) {
  fs::path target(path);
  fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir)) throw std::runtime_error(path + ": the folder " + dir.string() + " does not exist");
  return dir;
}

void writeAtomically(const std::string& path, const std::function<void(const std::string& temp)>& write) {
  fs::path target(path);
  fs::path dir = existingFolder(path);
  // In the same folder, so the rename is atomic: a file appears only once complete.
  fs::path temp =
      dir / ("." + target.stem().string() + ".partial-" + std::to_string(::getpid()) + target.extension().string());
  try {
    write(temp.string());
    std::error_code renamed;
    fs::rename(temp, target, renamed);
    if (renamed) throw std::runtime_error(path + ": could not write the file (" + renamed.message() + ")");
  } catch (...) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw;
  }
}

void writeBytes(const std::string& shown, const std::string& file, const std::vector<uint8_t>& bytes) {
  std::ofstream out(file, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  out.close();
  if (!out) throw std::runtime_error(shown + ": could not write the file");
}

}  // namespace snell::io
