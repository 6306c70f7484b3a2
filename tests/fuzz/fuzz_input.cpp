#include "fuzz_input.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string_view>

#include <unistd.h>

namespace snell::fuzz {

namespace fs = std::filesystem;

namespace {

// One folder per process (libFuzzer's -fork and -jobs run several), in
// memory where /dev/shm exists, removed at exit.
const fs::path& folder() {
  static const fs::path dir = [] {
    fs::path base = fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
    fs::path d = base / ("snell-fuzz-" + std::to_string(::getpid()));
    fs::create_directories(d);
    std::atexit([] {
      std::error_code ignored;
      fs::remove_all(folder(), ignored);
    });
    return d;
  }();
  return dir;
}

bool safeName(std::string_view name) {
  if (name.empty() || name.size() > 64 || name[0] == '.') return false;
  for (char c : name) {
    bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
              c == '-';
    if (!ok) return false;
  }
  return true;
}

void write(const fs::path& path, std::string_view bytes) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();  // the harness itself is broken, not snell
  if (!bytes.empty()) std::fwrite(bytes.data(), 1, bytes.size(), f);
  std::fclose(f);
}

}  // namespace

FileSet::FileSet(const uint8_t* data, size_t size) {
  std::string_view input(reinterpret_cast<const char*>(data), size);
  std::string_view marker(kFileMarker);
  size_t end = input.find(marker);
  document_ = (folder() / "scene.gltf").string();
  write(document_, input.substr(0, end));
  written_.push_back(document_);
  while (end != std::string_view::npos) {
    size_t nameStart = end + marker.size();
    size_t nameEnd = input.find('\n', nameStart);
    if (nameEnd == std::string_view::npos) break;
    size_t next = input.find(marker, nameEnd + 1);
    std::string_view name = input.substr(nameStart, nameEnd - nameStart);
    std::string_view bytes = input.substr(nameEnd + 1, next == std::string_view::npos ? next : next - nameEnd - 1);
    if (safeName(name) && name != "scene.gltf") {
      std::string path = (folder() / std::string(name)).string();
      write(path, bytes);
      written_.push_back(path);
    }
    end = next;
  }
}

FileSet::~FileSet() {
  for (const std::string& path : written_) std::remove(path.c_str());
}

std::vector<std::string> splitArguments(const uint8_t* data, size_t size) {
  std::vector<std::string> args(1);
  for (size_t i = 0; i < size; ++i) {
    if (data[i] == 0) {
      args.emplace_back();
    } else {
      args.back().push_back(char(data[i]));
    }
  }
  return args;
}

}  // namespace snell::fuzz
