// The EXR module (see exr_codec.h): OpenImageIO behind the ExrCodec interface.
#include "io/exr_codec.h"

#include <OpenImageIO/imageio.h>
#include <glm/gtc/packing.hpp>

#include <cstddef>
#include <cstring>
#include <stdexcept>

namespace snell::io {
namespace {

class OpenImageIoCodec final : public ExrCodec {
 public:
  // One EXR part: R, G, B, A then each AOV layer's channels, every channel in
  // its own type (half or float colour, float or uint AOVs), so ids stay exact.
  void write(const std::string& path, const std::string& temp, const LinearImage& image, const ImageExtras& extras,
             const std::string& software) const override {
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
    spec.attribute("Software", software);
    for (const auto& [name, value] : extras.text) spec.attribute(name, value);
    for (const auto& [name, value] : extras.numbers) spec.attribute(name, value);
    if (extras.hasWorldToCamera) spec.attribute("worldToCamera", OIIO::TypeMatrix, &extras.worldToCamera);
    auto out = OIIO::ImageOutput::create(temp);
    if (!out) throw std::runtime_error(path + ": cannot write EXR (" + OIIO::geterror() + ")");
    if (!out->open(temp, spec) || !out->write_image(OIIO::TypeDesc::UNKNOWN, packed.data()) || !out->close()) {
      throw std::runtime_error(path + ": " + out->geterror());
    }
}

  void writeRgbaFloat(const std::string& path, const std::string& temp, uint32_t width, uint32_t height,
                      const std::vector<float>& rgba, const std::string& content) const override {
    OIIO::ImageSpec spec(int(width), int(height), 4, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"R", "G", "B", "A"};
    spec.attribute("compression", "zip");
    if (!content.empty()) spec.attribute("snell:content", content);
    auto out = OIIO::ImageOutput::create(temp);
    if (!out) throw std::runtime_error(path + ": cannot write EXR (" + OIIO::geterror() + ")");
    if (!out->open(temp, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, rgba.data()) || !out->close()) {
      throw std::runtime_error(path + ": " + out->geterror());
    }
  }

  std::vector<float> read(const std::string& path, uint32_t& width, uint32_t& height, int& channels) const override {
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw std::runtime_error(path + ": cannot read (" + OIIO::geterror() + ")");
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels < 1 || spec.width > 65536 || spec.height > 65536) {
      throw std::runtime_error(path + ": an image of " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                               " pixels and " + std::to_string(spec.nchannels) + " channels cannot be used");
    }
    width = uint32_t(spec.width);
    height = uint32_t(spec.height);
    channels = spec.nchannels;
    std::vector<float> pixels(size_t(width) * height * size_t(channels));
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data())) {
      throw std::runtime_error(path + ": cannot read the pixels (" + in->geterror() + ")");
    }
    return pixels;
  }
};

}  // namespace
}  // namespace snell::io

extern "C" const snell::io::ExrCodec* snell_exr_codec() {
  static const snell::io::OpenImageIoCodec codec;
  return &codec;
}
