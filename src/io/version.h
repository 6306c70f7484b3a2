// snell's version, for --version, the JSON heads and the files' metadata.
#pragma once

namespace snell::io {

/// As `snell --version` prints it: CMake's project version.
const char* version();

}  // namespace snell::io
