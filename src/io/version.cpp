#include "io/version.h"

#ifndef SNELL_VERSION
#error "SNELL_VERSION comes from CMake's project version"
#endif

namespace snell::io {

const char* version() { return SNELL_VERSION; }

}  // namespace snell::io
