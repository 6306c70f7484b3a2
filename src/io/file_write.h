// Writing files whole: the light half of image writing, which every host
// links (the public API's PNG writer among them) without OpenImageIO or the
// glTF loader that io's image files bring.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace snell::io {

/// Encodes linear [0, 1] to 8-bit sRGB, rounding to nearest (NaN as 0).
uint8_t linearToSrgb8(float linear);

/// The folder `path` goes in; a std::runtime_error naming `path` where it does not exist.
std::filesystem::path existingFolder(const std::string& path);

/// Writes `path` complete or not at all: `write` fills a temporary file
/// beside it (the name it is given), which is renamed into place once
/// `write` returns. Throws std::runtime_error naming `path` (a missing
/// folder, a failed write or rename) and leaves no file behind.
void writeAtomically(const std::string& path, const std::function<void(const std::string& temp)>& write);

/// Writes `bytes` to `file`; a failure is a std::runtime_error naming `shown`.
void writeBytes(const std::string& shown, const std::string& file, const std::vector<uint8_t>& bytes);

}  // namespace snell::io
