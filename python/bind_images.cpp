// None
#include "module_support.h"

namespace snell_python {

void bindImages(py::module_& m) {
  m.def("version", &snell::version, "snell's version, 'major.minor.patch'.");
  m.def(
      "methods",
      [] {
        std::vector<std::pair<std::string, std::string>> all;
        for (const snell::MethodDescription& d : snell::methods()) all.emplace_back(d.name, d.summary);
        return all;
      },
      "The ways of drawing glass View(method=...) takes: (name, one-line summary) pairs.");
  m.def(
      "read_image_file",
      [](const std::string& path) -> py::array {
        snell::ImageFile image;
        {
          py::gil_scoped_release release;
          image = snell::readImageFile(path);
        }
        // array_t<T> takes its strides from sizeof(T): a py::array made from a py::dtype takes them from
        // the dtype's itemsize, which Debian's pybind11 (2.10) reads wrongly under numpy 2 (a plain venv's),
        // giving every sample the first one's bytes.
        auto samples = [&image](auto zero) -> py::array {
          py::array_t<decltype(zero)> out({py::ssize_t(image.height), py::ssize_t(image.width),
                                           py::ssize_t(image.channels)});
          std::memcpy(out.mutable_data(), image.data.data(), image.data.size());
          return out;
        };
        return image.bits == 32 ? samples(float{}) : image.bits == 16 ? samples(uint16_t{}) : samples(uint8_t{});
      },
      "path"_a,
      "An image file's samples as stored, (height, width, channels) with row 0 at the top: uint8, uint16 "
      "(16-bit PNG) or float32 (Radiance HDR). Decoded by stb_image, as snell's glTF loader decodes textures: "
      "PNG, JPEG, TGA, BMP, PSD, GIF, HDR, PIC, PNM; anything else raises snell.Error naming the file.");
  m.def(
      "write_png",
      [](const std::string& path, const py::array_t<float, py::array::c_style | py::array::forcecast>& rgba,
         bool alpha) {
        if (rgba.ndim() != 3 || rgba.shape(2) != 4) {
          throw snell::Error(path + ": the picture must be (height, width, 4) RGBA");
        }
        const float* data = rgba.data();
        auto width = uint32_t(rgba.shape(1)), height = uint32_t(rgba.shape(0));
        py::gil_scoped_release release;
        snell::writePng(path, width, height, data, alpha);
      },
      "path"_a, "rgba"_a, "alpha"_a = false,
      "Writes a (height, width, 4) scene-linear picture as an 8-bit sRGB PNG, as `snell render` does: complete "
      "or not at all (a temporary file renamed). Alpha is kept with alpha=True, else the PNG is opaque.");
}

}  // namespace snell_python
