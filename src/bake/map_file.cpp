#include "bake/map_file.h"

#include "io/image_file.h"
#include "scene/png.h"

#include <stdexcept>

namespace snell::bake {

void writeMapFile(const std::string& path, const MapPixels& pixels, Encoding encoding) {
  std::string ext = io::lowerExtension(path);
  const char* wanted = encoding == Encoding::Exr ? ".exr" : ".png";
  if (ext != wanted) {
    throw std::runtime_error(path + ": a " + encodingName(encoding) + " map is written as " + wanted + ", not '" + ext +
                             "'");
  }
  switch (encoding) {
    case Encoding::Sky8: io::writeBytesFile(path, scene::encodePng(pixels.width, pixels.height, pixels.sky8)); return;
    case Encoding::Rg16: io::writeBytesFile(path, scene::encodePng16(pixels.width, pixels.height, pixels.rg16)); return;
    case Encoding::Exr:
      io::writeRgbaFloatExr(path, pixels.width, pixels.height, pixels.rgba32f,
                            "refraction map: R, G the UV; A 1 lands, 0.5 marked, 0 not glass");
      return;
  }
}

MapPixels readMapFile(const std::string& path, Encoding& encoding) {
  MapPixels pixels;
  if (io::lowerExtension(path) == ".exr") {
    pixels.rgba32f = io::readRgbaFloatExr(path, pixels.width, pixels.height);
    encoding = Encoding::Exr;
    return pixels;
  }
  io::PngRgba png = io::readPngRgba(path);
  pixels.width = png.width;
  pixels.height = png.height;
  if (png.bits == 8) {
    encoding = Encoding::Sky8;
    pixels.sky8 = std::move(png.rgba8);
  } else {
    encoding = Encoding::Rg16;
    pixels.rg16 = std::move(png.rgba16);
  }
  return pixels;
}

}  // namespace snell::bake
