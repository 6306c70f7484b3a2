#include "io/image_compare.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace snell::io {

double ImageDifference::rmse() const { return channels ? std::sqrt(sumSquares / double(channels)) / 255.0 : 0.0; }

void ImageDifference::add(const ImageDifference& other) {
  pixels += other.pixels;
  channels += other.channels;
  over1 += other.over1;
  over8 += other.over8;
  sumSquares += other.sumSquares;
  maximum = std::max(maximum, other.maximum);
  if (!firstMismatch) firstMismatch = other.firstMismatch;
}

ImageDifference compareImages(const Rgb8Image& got, const Rgb8Image& want, const std::vector<bool>* only,
                              std::vector<uint8_t>* worst) {
  if (got.width != want.width || got.height != want.height) {
    throw std::invalid_argument("compareImages: a " + std::to_string(got.width) + "x" + std::to_string(got.height) +
                                " image against a " + std::to_string(want.width) + "x" + std::to_string(want.height) +
                                " one");
  }
  const size_t pixels = size_t(want.width) * want.height;
  if (worst) worst->assign(pixels, 0);
  ImageDifference d;
  for (size_t i = 0; i < pixels; ++i) {
    int largest = 0;
    double squares = 0;
    for (size_t c = 0; c < 3; ++c) {
      int diff = std::abs(int(got.rgb[3 * i + c]) - int(want.rgb[3 * i + c]));
      largest = std::max(largest, diff);
      squares += double(diff) * diff;
    }
    if (worst) (*worst)[i] = uint8_t(largest);
    if (only && !(*only)[i]) continue;
    d.pixels += 1;
    d.channels += 3;
    d.sumSquares += squares;
    d.over1 += largest > 1;
    d.over8 += largest > 8;
    d.maximum = std::max(d.maximum, largest);
    if (largest > 1 && !d.firstMismatch) d.firstMismatch = {uint32_t(i % want.width), uint32_t(i / want.width)};
  }
  return d;
}

}  // namespace snell::io
