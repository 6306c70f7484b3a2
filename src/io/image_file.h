// Image files: PNG (8-bit sRGB, deflated) and EXR through OpenImageIO (linear
// half or float, alpha = coverage, metadata, AOV layers), written atomically so
// a failed or interrupted write leaves nothing behind.
#pragma once

#include "io/file_write.h"  // linearToSrgb8, which callers of toSrgb8 use too

#include "scene/optics.h"

#include <glm/glm.hpp>
#include <glm/gtc/packing.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace snell::io {

/// Linear RGBA, row 0 at the top: as floats, or as the GPU's half floats read
/// back as they are (then converted once, where the file is encoded).
struct LinearImage {
  uint32_t width = 0, height = 0;
  std::vector<glm::vec4> rgba;
  std::vector<uint16_t> rgbaHalf;  ///< used when rgba is empty: 4 IEEE halves per pixel

  size_t pixels() const { return size_t(width) * height; }
  /// Pixel i's channel c, whichever way the image is held.
  float channel(size_t i, int c) const {
    return rgba.empty() ? glm::unpackHalf1x16(rgbaHalf[4 * i + size_t(c)]) : rgba[i][c];
  }
};

/// Extra channels for an EXR, named the way compositors read layers:
/// LAYER.CHANNEL (depth.Z, normal.X, instance.id).
struct AovLayer {
  std::string layer;
  std::vector<std::string> channels;
  bool integer = false;         ///< 32-bit unsigned (ids, counts) rather than float
  std::vector<float> values;    ///< float layers: pixels * channels, interleaved
  std::vector<uint32_t> ids;    ///< integer layers: the same
};

/// What an EXR carries beyond its colour; a PNG takes none of it.
struct ImageExtras {
  bool floatPixels = false;  ///< RGBA (and float AOVs) as 32-bit float rather than half
  std::vector<AovLayer> aovs;
  /// Header attributes: "snell:camera" and the like, strings...
  std::vector<std::pair<std::string, std::string>> text;
  /// ...and numbers ("snell:time").
  std::vector<std::pair<std::string, float>> numbers;
  /// The standard EXR worldToCamera matrix, when the camera is known.
  bool hasWorldToCamera = false;
  glm::mat4 worldToCamera{1.0f};
};

/// Writes `image` to `path` (format from the extension: .png or .exr): into a
/// temporary file beside it, renamed into place once complete. Throws
/// std::runtime_error naming the file and the problem; leaves no file then.
/// PNG ignores alpha (8-bit sRGB, opaque); EXR keeps it.
void writeImage(const std::string& path, const LinearImage& image, const ImageExtras& extras = {});

/// Writes bytes already encoded (a PNG's, say): complete, or not at all.
void writeBytesFile(const std::string& path, const std::vector<uint8_t>& bytes);
/// Writes 4 float channels (R, G, B, A: data, not colour) to a zip-compressed
/// EXR, with `content` in its "snell:content" attribute. Throws naming the
/// file where the build has no OpenImageIO.
void writeRgbaFloatExr(const std::string& path, uint32_t width, uint32_t height, const std::vector<float>& rgba,
                       const std::string& content);
/// Reads one back as floats; anything but 4 channels is an error naming the file.
std::vector<float> readRgbaFloatExr(const std::string& path, uint32_t& width, uint32_t& height);

/// An RGBA PNG's samples as stored: 8 or 16 bits (native-endian) per channel.
struct PngRgba {
  uint32_t width = 0, height = 0, bits = 8;
  std::vector<uint8_t> rgba8;
  std::vector<uint16_t> rgba16;
};
PngRgba readPngRgba(const std::string& path);

/// The path's extension in lower case, with its dot (".png").
std::string lowerExtension(const std::string& path);

/// Writes `text` to `path` the same way: complete, or not at all.
void writeTextFile(const std::string& path, const std::string& text);

/// Fails now, before any work is done, where `path` could not be written at the
/// end: its folder is missing or not writable, or the path is a folder. Throws
/// std::runtime_error naming the path and the problem.
void checkWritable(const std::string& path);

/// Reads an 8-bit-per-channel image (a golden PNG) as RGB bytes.
struct Rgb8Image {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgb;
};
Rgb8Image readRgb8(const std::string& path);
void writeRgb8(const std::string& path, const Rgb8Image& image);
/// Reads an equirectangular environment (HDR or EXR through OpenImageIO, or
/// an 8-bit PNG decoded from sRGB), fitted by scene::fitEnvironment. Throws
/// std::runtime_error naming the file and the problem.
scene::Environment readEnvironment(const std::string& path);
/// The image as 8-bit sRGB, as writeImage would put it in a PNG.
Rgb8Image toSrgb8(const LinearImage& image);

}  // namespace snell::io
