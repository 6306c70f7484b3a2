// How the fuzz targets turn libFuzzer's bytes into what snell reads: a glTF
// document with the files beside it, or a command line.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace snell::fuzz {

/// The separator between packed files. An input is
///   DOCUMENT ( "\n#snell-fuzz-file NAME\n" BYTES )*
/// so a seed is a .gltf followed by its .bin and images (scripts/fuzz packs
/// them), and mutations reach the external files as well as the JSON.
inline constexpr const char* kFileMarker = "\n#snell-fuzz-file ";

/// The input unpacked into this process's private folder: the document as
/// "scene.gltf" (the loader tells .glb apart by content), the others under
/// their names (only [A-Za-z0-9._-], so nothing escapes the folder). The
/// folder is emptied again when the FileSet goes.
class FileSet {
 public:
  FileSet(const uint8_t* data, size_t size);
  ~FileSet();
  FileSet(const FileSet&) = delete;
  FileSet& operator=(const FileSet&) = delete;

  const std::string& document() const { return document_; }

 private:
  std::vector<std::string> written_;
  std::string document_;
};

/// Arguments separated by NUL bytes, as a shell would hand them over.
std::vector<std::string> splitArguments(const uint8_t* data, size_t size);

}  // namespace snell::fuzz
