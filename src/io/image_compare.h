// One way to compare two 8-bit images, for the golden tests, the method
// benchmark and the stability grid: per pixel the largest channel difference,
// in 1/255 units, as a PNG would hold the pixels.
#pragma once

#include "io/image_file.h"

#include <cstdint>
#include <optional>
#include <vector>

namespace snell::io {

/// Differences summed over the pixels compared (of one image, or of a whole
/// sequence: add() one to another).
struct ImageDifference {
  uint64_t pixels = 0, channels = 0;
  uint64_t over1 = 0, over8 = 0;  ///< pixels with a channel more than 1/255, 8/255 apart
  double sumSquares = 0;          ///< of channel differences, in 1/255 units
  int maximum = 0;                ///< the largest channel difference, in 1/255 units
  /// The first pixel (x, y) over 1/255, in row order.
  std::optional<std::pair<uint32_t, uint32_t>> firstMismatch;

  /// Root mean square of the channel differences, in [0, 1].
  double rmse() const;
  /// `n` pixels as a share of those compared.
  double share(uint64_t n) const { return pixels ? double(n) / double(pixels) : 0.0; }
  void add(const ImageDifference& other);
};

/// Compares `got` against `want` (the same size, or std::invalid_argument),
/// over every pixel, or only where `only` is true. `worst`, when given,
/// receives each pixel's largest channel difference.
ImageDifference compareImages(const Rgb8Image& got, const Rgb8Image& want, const std::vector<bool>* only = nullptr,
                              std::vector<uint8_t>* worst = nullptr);

}  // namespace snell::io
