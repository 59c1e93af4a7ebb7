#include "render/image_difference.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace render {

ImageDifference image_difference(const Image& image, const Image& reference, float coverage) {
  if (image.width != reference.width || image.height != reference.height) {
    std::string why = "the images differ in size: ";
    why += std::to_string(image.width) + " x " + std::to_string(image.height) + " against ";
    why += std::to_string(reference.width) + " x " + std::to_string(reference.height);
    throw std::invalid_argument(why);
  }
  ImageDifference e;
  double squared = 0.0, reference_squared = 0.0, absolute = 0.0;
  const std::size_t n = std::size_t(image.width) * std::size_t(image.height);
  for (std::size_t i = 0; i < n; ++i) {
    const float* a = image.rgba.data() + 4 * i;
    const float* r = reference.rgba.data() + 4 * i;
    if (a[3] < coverage || r[3] < coverage) continue;
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(a[c]) || !std::isfinite(r[c]))
        throw std::invalid_argument("pixel " + std::to_string(i % image.width) + ", " +
                                    std::to_string(i / image.width) + " is not finite");
      const double d = double(a[c]) - double(r[c]);
      squared += d * d;
      reference_squared += double(r[c]) * double(r[c]);
      absolute += std::abs(d);
      e.max_abs = std::max(e.max_abs, std::abs(d));
    }
    ++e.pixels;
  }
  if (e.pixels == 0)
    throw std::invalid_argument("no pixel is covered in both images (alpha below coverage)");
  const double values = 3.0 * double(e.pixels);
  e.rmse = std::sqrt(squared / values);
  e.mean_abs = absolute / values;
  e.relative_rmse = reference_squared > 0 ? e.rmse / std::sqrt(reference_squared / values) : 0.0;
  return e;
}

}  // namespace render
