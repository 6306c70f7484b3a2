// Refraction map files: a map's pixels (refraction_bake.h's encodings) as a
// PNG or an EXR, written through io's atomic writes.
#pragma once

#include "bake/refraction_bake.h"

#include <string>

namespace snell::bake {

/// Writes a refraction map file as `encoding` asks (rg16 and sky8: PNG,
/// 16-bit and 8-bit RGBA; exr: float RGBA), complete or not at all. Throws
/// std::runtime_error naming the file when its extension does not fit.
void writeMapFile(const std::string& path, const MapPixels& pixels, Encoding encoding);
/// Reads one back; the encoding follows from the file (8-bit PNG: sky8,
/// 16-bit PNG: rg16, EXR: exr).
MapPixels readMapFile(const std::string& path, Encoding& encoding);

}  // namespace snell::bake
