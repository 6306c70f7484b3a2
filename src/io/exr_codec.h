// EXR (and OpenImageIO's other float formats: HDR) in a module of its own,
// libsnell_exr.so, which snell opens the first time a file needs it:
// OpenImageIO brings some 265 shared libraries that took a process 0.2 s to
// load before any work, and most runs write PNG. image_file.cpp is its one
// user; the module (exr_codec.cpp) is the one place that includes OpenImageIO.
#pragma once

#include "io/image_file.h"

#include <cstdint>
#include <string>
#include <vector>

namespace snell::io {

class ExrCodec {
 public:
  virtual ~ExrCodec() = default;
  /// One EXR part of `image` and its extras, into `temp` (`path`, the file
  /// it becomes, names it in messages); `software` goes in its header.
  virtual void write(const std::string& path, const std::string& temp, const LinearImage& image,
                     const ImageExtras& extras, const std::string& software) const = 0;
  /// Four float channels (data, not colour), zip-compressed, with "snell:content" unless empty.
  virtual void writeRgbaFloat(const std::string& path, const std::string& temp, uint32_t width, uint32_t height,
                              const std::vector<float>& rgba, const std::string& content) const = 0;
  /// Every channel of the file's first image as float, `channels` a pixel.
  virtual std::vector<float> read(const std::string& path, uint32_t& width, uint32_t& height, int& channels) const = 0;
};

/// The codec, its module opened on the first call. Throws std::runtime_error
/// naming `path` where the build has no OpenImageIO or the module cannot be loaded.
const ExrCodec& exrCodec(const std::string& path);

}  // namespace snell::io

/// The module's one entry (dlsym'd by exrCodec).
extern "C" const snell::io::ExrCodec* snell_exr_codec();
