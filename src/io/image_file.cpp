// PNG through snell's own encoder (src/scene/png.h) and tinygltf's
// decoder, EXR through OpenImageIO in a module opened when a file needs it
// (exr_codec.h), where the build has it; the rename makes every write
// all-or-nothing. Without OpenImageIO the binary carries to a machine that
// has only the Vulkan loader (the GPU benchmarks do that).
#include "io/image_file.h"

#include "io/exr_codec.h"
#include "io/file_write.h"
#include "io/version.h"
#include "scene/png.h"
#include "scene/scene.h"

#include <dlfcn.h>
#include <glm/gtc/packing.hpp>
#include <tiny_gltf.h>

#include <fstream>
#include <mutex>
#include <iterator>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <fcntl.h>
#include <unistd.h>

namespace snell::io {

namespace fs = std::filesystem;

const ExrCodec& exrCodec(const std::string& path) {
#if SNELL_WITH_OPENIMAGEIO
  // Beside an installed command (SNELL_EXR_MODULE_INSTALLED, from its folder),
  // else where the build made it (the build tree's commands and tests).
  static const ExrCodec* codec = nullptr;
  static std::string why;
  static std::once_flag opened;
  std::call_once(opened, [] {
    std::error_code error;
    const fs::path self = fs::read_symlink("/proc/self/exe", error);
    std::vector<std::string> candidates;
    if (!error) candidates.push_back((self.parent_path() / SNELL_EXR_MODULE_INSTALLED).lexically_normal().string());
    candidates.push_back(SNELL_EXR_MODULE);
    for (const std::string& candidate : candidates) {
      if (!fs::exists(candidate)) continue;
      void* module = dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL);
      auto entry = module ? reinterpret_cast<const ExrCodec* (*)()>(dlsym(module, "snell_exr_codec")) : nullptr;
      if (entry) {
        codec = entry();
        return;
      }
      why = candidate + ": " + dlerror();
      return;
    }
    why = "no " + candidates.back() + " (nor one beside the command)";
  });
  if (codec) return *codec;
  throw std::runtime_error(path + ": EXR needs snell's OpenImageIO module, which did not load (" + why + ")");
#else
  throw std::runtime_error(path + ": this build has no OpenImageIO, so no EXR; write a .png");
#endif
}

Rgb8Image toSrgb8(const LinearImage& image) {
  Rgb8Image out{image.width, image.height, std::vector<uint8_t>(image.pixels() * 3)};
  if (image.rgba.empty()) {
    // Every half maps straight to its byte: one table, one conversion per sample.
    static const std::vector<uint8_t> halfToSrgb = [] {
      std::vector<uint8_t> table(65536);
      for (uint32_t h = 0; h < 65536; ++h) table[h] = linearToSrgb8(glm::unpackHalf1x16(uint16_t(h)));
      return table;
    }();
    for (size_t i = 0; i < image.pixels(); ++i) {
      for (int c = 0; c < 3; ++c) out.rgb[3 * i + size_t(c)] = halfToSrgb[image.rgbaHalf[4 * i + size_t(c)]];
    }
    return out;
  }
  for (size_t i = 0; i < image.rgba.size(); ++i) {
    for (int c = 0; c < 3; ++c) out.rgb[3 * i + size_t(c)] = linearToSrgb8(image.rgba[i][c]);
  }
  return out;
}

namespace {

std::vector<uint8_t> pngBytes(uint32_t width, uint32_t height, const std::vector<uint8_t>& rgb) {
  std::vector<uint8_t> rgba(size_t(width) * height * 4, 255);
  for (size_t i = 0; i < size_t(width) * height; ++i) {
    for (int c = 0; c < 3; ++c) rgba[4 * i + size_t(c)] = rgb[3 * i + size_t(c)];
  }
  return scene::encodePng(width, height, rgba);
}

}  // namespace

void writeImage(const std::string& path, const LinearImage& image, const ImageExtras& extras) {
  std::string ext = lowerExtension(path);
  if (ext != ".png" && ext != ".exr") {
    throw std::runtime_error(path + ": unsupported image type '" + ext + "' (use .png or .exr)");
  }
  if (ext == ".png" && !extras.aovs.empty()) throw std::runtime_error(path + ": AOV layers need an .exr file");
  // Before any file is made: a build without OpenImageIO, or a module that does not load, refuses here.
  const ExrCodec* exr = ext == ".exr" ? &exrCodec(path) : nullptr;
  if ((image.rgba.empty() ? image.rgbaHalf.size() / 4 : image.rgba.size()) != image.pixels()) {
    throw std::runtime_error(path + ": the pixels do not fill a " + std::to_string(image.width) + "x" +
                             std::to_string(image.height) + " image");
  }
  writeAtomically(path, [&](const std::string& temp) {
    if (ext == ".png") {
      writeBytes(path, temp, pngBytes(image.width, image.height, toSrgb8(image).rgb));
      return;
    }
    exr->write(path, temp, image, extras, std::string("snell ") + version());
  });
}

void writeRgb8(const std::string& path, const Rgb8Image& image) {
  writeAtomically(path, [&](const std::string& temp) { writeBytes(path, temp, pngBytes(image.width, image.height, image.rgb)); });
}

namespace {

// A PNG file decoded by stb (through tinygltf) to RGBA of 8 or 16 bits.
tinygltf::Image decodeImageFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  tinygltf::Image decoded;
  std::string err, warn;
  if (!tinygltf::LoadImageData(&decoded, 0, &err, &warn, 0, 0, bytes.data(), int(bytes.size()), nullptr)) {
    throw std::runtime_error(path + ": not an image snell reads " + err);
  }
  return decoded;
}

}  // namespace

Rgb8Image readRgb8(const std::string& path) {
  tinygltf::Image decoded = decodeImageFile(path);
  if (decoded.bits != 8 || decoded.component < 3) throw std::runtime_error(path + ": not an 8-bit RGB(A) image");
  Rgb8Image image{uint32_t(decoded.width), uint32_t(decoded.height), {}};
  size_t pixels = size_t(decoded.width) * size_t(decoded.height);
  image.rgb.resize(pixels * 3);
  for (size_t i = 0; i < pixels; ++i) {
    for (int c = 0; c < 3; ++c) image.rgb[3 * i + size_t(c)] = decoded.image[size_t(decoded.component) * i + size_t(c)];
  }
  return image;
}


scene::Environment readEnvironment(const std::string& path) {
  if (!fs::is_regular_file(path)) throw std::runtime_error(path + ": no such environment file");
  scene::Environment env;
  env.source = path;
  std::string ext = lowerExtension(path);
  if (ext == ".png") {
    Rgb8Image image = readRgb8(path);
    env.width = image.width;
    env.height = image.height;
    env.texels.resize(size_t(image.width) * image.height);
    for (size_t i = 0; i < env.texels.size(); ++i) {
      for (int c = 0; c < 3; ++c) env.texels[i][c] = float(scene::srgbToLinear(image.rgb[3 * i + size_t(c)]));
    }
  } else {
    int channels = 0;
    const std::vector<float> pixels = exrCodec(path).read(path, env.width, env.height, channels);
    env.texels.resize(size_t(env.width) * env.height);
    for (size_t i = 0; i < env.texels.size(); ++i) {
      for (int c = 0; c < 3; ++c) env.texels[i][c] = pixels[i * size_t(channels) + size_t(std::min(c, channels - 1))];
    }
  }
  scene::fitEnvironment(env);
  return env;
}

void writeBytesFile(const std::string& path, const std::vector<uint8_t>& bytes) {
  writeAtomically(path, [&](const std::string& temp) { writeBytes(path, temp, bytes); });
}

void writeRgbaFloatExr(const std::string& path, uint32_t width, uint32_t height, const std::vector<float>& rgba,
                       const std::string& content) {
  if (lowerExtension(path) != ".exr") throw std::runtime_error(path + ": not an .exr name");
  const ExrCodec& codec = exrCodec(path);
  writeAtomically(path, [&](const std::string& temp) { codec.writeRgbaFloat(path, temp, width, height, rgba, content); });
}

std::vector<float> readRgbaFloatExr(const std::string& path, uint32_t& width, uint32_t& height) {
  int channels = 0;
  std::vector<float> rgba = exrCodec(path).read(path, width, height, channels);
  if (channels != 4) {
    throw std::runtime_error(path + ": 4 channels (RGBA) were expected, this has " + std::to_string(channels));
  }
  return rgba;
}

PngRgba readPngRgba(const std::string& path) {
  tinygltf::Image decoded = decodeImageFile(path);
  if (decoded.component != 4 || (decoded.bits != 8 && decoded.bits != 16)) {
    throw std::runtime_error(path + ": an RGBA PNG of 8 or 16 bits was expected");
  }
  PngRgba png{uint32_t(decoded.width), uint32_t(decoded.height), uint32_t(decoded.bits), {}, {}};
  if (decoded.bits == 8) {
    png.rgba8.assign(decoded.image.begin(), decoded.image.end());
  } else {
    png.rgba16.resize(decoded.image.size() / 2);
    std::memcpy(png.rgba16.data(), decoded.image.data(), decoded.image.size());  // stb gives native-endian samples
  }
  return png;
}

std::string lowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

void checkWritable(const std::string& path) {
  fs::path dir = existingFolder(path);
  if (fs::is_directory(path)) throw std::runtime_error(path + ": is a folder, not a file");
  // The only sure test is to make a file there, as the final write will.
  fs::path probe = dir / (".snell-write-check-" + std::to_string(::getpid()));
  int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
  if (fd < 0) {
    throw std::runtime_error(path + ": cannot write in the folder " + dir.string() + " (" + std::strerror(errno) + ")");
  }
  ::close(fd);
  ::unlink(probe.c_str());
}

void writeTextFile(const std::string& path, const std::string& text) {
  writeAtomically(path, [&](const std::string& temp) {
    writeBytes(path, temp, std::vector<uint8_t>(text.begin(), text.end()));
  });
}

}  // namespace snell::io
