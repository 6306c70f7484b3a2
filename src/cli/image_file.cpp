// OpenImageIO writes and reads; the rename makes writes all-or-nothing.
#include "cli/image_file.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <unistd.h>

namespace snell::cli {

namespace fs = std::filesystem;

uint8_t linearToSrgb8(float linear) {
  float c = std::clamp(std::isnan(linear) ? 0.0f : linear, 0.0f, 1.0f);
  float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return static_cast<uint8_t>(std::lround(s * 255.0f));
}

Rgb8Image toSrgb8(const LinearImage& image) {
  Rgb8Image out{image.width, image.height, std::vector<uint8_t>(size_t(image.width) * image.height * 3)};
  for (size_t i = 0; i < image.rgba.size(); ++i) {
    for (int c = 0; c < 3; ++c) out.rgb[3 * i + size_t(c)] = linearToSrgb8(image.rgba[i][c]);
  }
  return out;
}

namespace {

std::string lowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

// Writes through a temporary file in the same folder, so the rename is atomic.
template <typename WriteFn>
void writeAtomically(const std::string& path, WriteFn write) {
  fs::path target(path);
  fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir)) throw std::runtime_error(path + ": the folder " + dir.string() + " does not exist");
  fs::path temp = dir / ("." + target.stem().string() + ".partial-" + std::to_string(::getpid()) + target.extension().string());
  try {
    write(temp.string());
    fs::rename(temp, target);
  } catch (...) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw;
  }
}

void writePixels(const std::string& finalPath, const std::string& path, const OIIO::ImageSpec& spec, const void* pixels,
                 OIIO::TypeDesc type) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw std::runtime_error(finalPath + ": cannot write this format (" + OIIO::geterror() + ")");
  if (!out->open(path, spec) || !out->write_image(type, pixels) || !out->close()) {
    throw std::runtime_error(finalPath + ": " + out->geterror());
  }
}

}  // namespace

void writeImage(const std::string& path, const LinearImage& image) {
  std::string ext = lowerExtension(path);
  if (ext != ".png" && ext != ".exr") {
    throw std::runtime_error(path + ": unsupported image type '" + ext + "' (use .png or .exr)");
  }
  writeAtomically(path, [&](const std::string& temp) {
    if (ext == ".png") {
      Rgb8Image srgb = toSrgb8(image);
      OIIO::ImageSpec spec(int(image.width), int(image.height), 3, OIIO::TypeDesc::UINT8);
      spec.attribute("oiio:ColorSpace", "sRGB");
      writePixels(path, temp, spec, srgb.rgb.data(), OIIO::TypeDesc::UINT8);
    } else {
      OIIO::ImageSpec spec(int(image.width), int(image.height), 4, OIIO::TypeDesc::HALF);
      spec.attribute("oiio:ColorSpace", "Linear");
      spec.attribute("compression", "zip");
      writePixels(path, temp, spec, image.rgba.data(), OIIO::TypeDesc::FLOAT);
    }
  });
}

void writeRgb8(const std::string& path, const Rgb8Image& image) {
  writeAtomically(path, [&](const std::string& temp) {
    OIIO::ImageSpec spec(int(image.width), int(image.height), 3, OIIO::TypeDesc::UINT8);
    writePixels(path, temp, spec, image.rgb.data(), OIIO::TypeDesc::UINT8);
  });
}

Rgb8Image readRgb8(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw std::runtime_error(path + ": cannot read (" + OIIO::geterror() + ")");
  const OIIO::ImageSpec& spec = in->spec();
  Rgb8Image image{uint32_t(spec.width), uint32_t(spec.height), {}};
  image.rgb.resize(size_t(spec.width) * spec.height * 3);
  if (!in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, image.rgb.data())) {
    throw std::runtime_error(path + ": " + in->geterror());
  }
  return image;
}

}  // namespace snell::cli
