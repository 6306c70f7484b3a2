// PNG through snell's own encoder (src/scene/png.h) and tinygltf's
// decoder, EXR through OpenImageIO where the build has it; the rename makes
// every write all-or-nothing. Without OpenImageIO the binary carries to a
// machine that has only the Vulkan loader (the GPU benchmarks do that).
#include "io/image_file.h"

#include "io/file_write.h"
#include "io/version.h"
#include "scene/png.h"
#include "scene/scene.h"

#if SNELL_WITH_OPENIMAGEIO
#include <OpenImageIO/imageio.h>
#endif
#include <glm/gtc/packing.hpp>
#include <tiny_gltf.h>

#include <fstream>
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

float LinearImage::channel(size_t i, int c) const {
  return rgba.empty() ? glm::unpackHalf1x16(rgbaHalf[4 * i + size_t(c)]) : rgba[i][c];
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

#if SNELL_WITH_OPENIMAGEIO
namespace {

// One EXR part: R, G, B, A then each AOV layer's channels, every channel in
// its own type (half or float colour, float or uint AOVs), so ids stay exact.
void writeExr(const std::string& path, const std::string& temp, const LinearImage& image, const ImageExtras& extras) {
  const OIIO::TypeDesc colourType = extras.floatPixels ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::HALF;
  std::vector<OIIO::TypeDesc> formats(4, colourType);
  std::vector<std::string> names = {"R", "G", "B", "A"};
  for (const AovLayer& layer : extras.aovs) {
    size_t expected = image.pixels() * layer.channels.size();
    if ((layer.integer ? layer.ids.size() : layer.values.size()) != expected) {
      throw std::runtime_error(path + ": the " + layer.layer + " layer does not fill the image");
    }
    for (const std::string& c : layer.channels) {
      names.push_back(layer.layer + "." + c);
      formats.push_back(layer.integer ? OIIO::TypeDesc::UINT : extras.floatPixels ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::HALF);
    }
  }
  // The pixels packed as the file holds them, so OpenImageIO converts nothing.
  size_t pixelBytes = 0;
  for (const OIIO::TypeDesc& f : formats) pixelBytes += f.size();
  std::vector<std::byte> packed(pixelBytes * image.pixels());
  for (size_t i = 0; i < image.pixels(); ++i) {
    std::byte* at = packed.data() + i * pixelBytes;
    for (int c = 0; c < 4; ++c) {
      if (extras.floatPixels) {
        float v = image.channel(i, c);
        std::memcpy(at, &v, 4), at += 4;
      } else {
        uint16_t h = image.rgba.empty() ? image.rgbaHalf[4 * i + size_t(c)] : glm::packHalf1x16(image.rgba[i][c]);
        std::memcpy(at, &h, 2), at += 2;
      }
    }
    for (const AovLayer& layer : extras.aovs) {
      for (size_t c = 0; c < layer.channels.size(); ++c) {
        size_t k = i * layer.channels.size() + c;
        if (layer.integer) {
          std::memcpy(at, &layer.ids[k], 4), at += 4;
        } else if (extras.floatPixels) {
          std::memcpy(at, &layer.values[k], 4), at += 4;
        } else {
          uint16_t h = glm::packHalf1x16(layer.values[k]);
          std::memcpy(at, &h, 2), at += 2;
        }
      }
    }
  }
  OIIO::ImageSpec spec(int(image.width), int(image.height), int(names.size()), colourType);
  spec.channelnames = names;
  spec.channelformats = formats;
  spec.alpha_channel = 3;
  spec.attribute("oiio:ColorSpace", "Linear");
  spec.attribute("compression", "zip");
  spec.attribute("Software", std::string("snell ") + version());
  for (const auto& [name, value] : extras.text) spec.attribute(name, value);
  for (const auto& [name, value] : extras.numbers) spec.attribute(name, value);
  if (extras.hasWorldToCamera) spec.attribute("worldToCamera", OIIO::TypeMatrix, &extras.worldToCamera);
  auto out = OIIO::ImageOutput::create(temp);
  if (!out) throw std::runtime_error(path + ": cannot write EXR (" + OIIO::geterror() + ")");
  if (!out->open(temp, spec) || !out->write_image(OIIO::TypeDesc::UNKNOWN, packed.data()) || !out->close()) {
    throw std::runtime_error(path + ": " + out->geterror());
  }
}

}  // namespace
#endif

void writeImage(const std::string& path, const LinearImage& image, const ImageExtras& extras) {
  std::string ext = lowerExtension(path);
  if (ext != ".png" && ext != ".exr") {
    throw std::runtime_error(path + ": unsupported image type '" + ext + "' (use .png or .exr)");
  }
  if (ext == ".png" && !extras.aovs.empty()) throw std::runtime_error(path + ": AOV layers need an .exr file");
#if !SNELL_WITH_OPENIMAGEIO
  if (ext == ".exr") throw std::runtime_error(path + ": this build has no OpenImageIO, so no EXR; write a .png");
#endif
  if ((image.rgba.empty() ? image.rgbaHalf.size() / 4 : image.rgba.size()) != image.pixels()) {
    throw std::runtime_error(path + ": the pixels do not fill a " + std::to_string(image.width) + "x" +
                             std::to_string(image.height) + " image");
  }
  writeAtomically(path, [&](const std::string& temp) {
    if (ext == ".png") {
      writeBytes(path, temp, pngBytes(image.width, image.height, toSrgb8(image).rgb));
      return;
    }
#if SNELL_WITH_OPENIMAGEIO
    writeExr(path, temp, image, extras);
#endif
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
#if SNELL_WITH_OPENIMAGEIO
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw std::runtime_error(path + ": cannot read the environment (" + OIIO::geterror() + ")");
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels < 1 || spec.width > 65536 || spec.height > 65536) {
      throw std::runtime_error(path + ": an environment of " + std::to_string(spec.width) + "x" +
                               std::to_string(spec.height) + " texels and " + std::to_string(spec.nchannels) +
                               " channels cannot be used");
    }
    env.width = uint32_t(spec.width);
    env.height = uint32_t(spec.height);
    int channels = spec.nchannels;
    std::vector<float> pixels(size_t(env.width) * env.height * size_t(channels));
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data())) {
      throw std::runtime_error(path + ": cannot read the environment's pixels (" + in->geterror() + ")");
    }
    env.texels.resize(size_t(env.width) * env.height);
    for (size_t i = 0; i < env.texels.size(); ++i) {
      for (int c = 0; c < 3; ++c) env.texels[i][c] = pixels[i * size_t(channels) + size_t(std::min(c, channels - 1))];
    }
#else
    throw std::runtime_error(path + ": this build has no OpenImageIO, so only .png environments");
#endif
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
#if SNELL_WITH_OPENIMAGEIO
  writeAtomically(path, [&](const std::string& temp) {
    OIIO::ImageSpec spec(int(width), int(height), 4, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"R", "G", "B", "A"};
    spec.attribute("compression", "zip");
    if (!content.empty()) spec.attribute("snell:content", content);
    auto out = OIIO::ImageOutput::create(temp);
    if (!out) throw std::runtime_error(path + ": cannot write EXR (" + OIIO::geterror() + ")");
    if (!out->open(temp, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, rgba.data()) || !out->close()) {
      throw std::runtime_error(path + ": " + out->geterror());
    }
  });
#else
  (void)width, (void)height, (void)rgba, (void)content;
  throw std::runtime_error(path + ": this build has no OpenImageIO, so no EXR");
#endif
}

std::vector<float> readRgbaFloatExr(const std::string& path, uint32_t& width, uint32_t& height) {
#if SNELL_WITH_OPENIMAGEIO
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw std::runtime_error(path + ": cannot read (" + OIIO::geterror() + ")");
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.nchannels != 4 || spec.width <= 0 || spec.height <= 0) {
    throw std::runtime_error(path + ": 4 channels (RGBA) were expected, this has " + std::to_string(spec.nchannels));
  }
  width = uint32_t(spec.width);
  height = uint32_t(spec.height);
  std::vector<float> rgba(size_t(width) * height * 4);
  if (!in->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, rgba.data())) {
    throw std::runtime_error(path + ": cannot read the pixels (" + in->geterror() + ")");
  }
  return rgba;
#else
  (void)width, (void)height;
  throw std::runtime_error(path + ": this build has no OpenImageIO, so no EXR");
#endif
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
