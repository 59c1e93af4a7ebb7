#include "render/image_difference.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace render {

namespace {

// The mask eroded by a (2 r + 1)^2 square: separable, a running count of uncovered pixels
// along each row, then each column (outside the image counts as uncovered).
std::vector<char> erode_mask(const std::vector<char>& mask, int width, int height, int r) {
  auto pass = [r](const std::vector<char>& in, int n, int lines, std::size_t step,
                  std::size_t line_step) {
    std::vector<char> out(in.size(), 0);
    for (int line = 0; line < lines; ++line) {
      const std::size_t base = std::size_t(line) * line_step;
      auto at = [&](int i) { return i >= 0 && i < n && in[base + std::size_t(i) * step]; };
      int holes = 0;  // uncovered pixels in [i - r, i + r]
      for (int i = -r; i <= r; ++i) holes += !at(i);
      for (int i = 0; i < n; ++i) {
        out[base + std::size_t(i) * step] = holes == 0;
        holes += !at(i + r + 1);
        holes -= !at(i - r);
      }
    }
    return out;
  };
  const std::vector<char> rows = pass(mask, width, height, 1, std::size_t(width));
  return pass(rows, height, width, std::size_t(width), 1);
}

void check_same_size(const Image& image, const Image& reference, const char* which) {
  if (image.width == reference.width && image.height == reference.height) return;
  std::string why = std::string(which) + " differ in size: ";
  why += std::to_string(image.width) + " x " + std::to_string(image.height) + " against ";
  why += std::to_string(reference.width) + " x " + std::to_string(reference.height);
  throw std::invalid_argument(why);
}

}  // namespace

ImageDifference image_difference(const Image& image, const Image& reference, float coverage,
                                 int erode, const Image* second_reference) {
  if (erode < 0) throw std::invalid_argument("erode must be >= 0");
  check_same_size(image, reference, "the images");
  if (second_reference) check_same_size(*second_reference, reference, "the references");
  ImageDifference e;
  double squared = 0.0, reference_squared = 0.0, absolute = 0.0, noise_squared = 0.0;
  const std::size_t n = std::size_t(image.width) * std::size_t(image.height);
  std::vector<char> compared(n);
  for (std::size_t i = 0; i < n; ++i)
    compared[i] = image.rgba[4 * i + 3] >= coverage && reference.rgba[4 * i + 3] >= coverage &&
                  (!second_reference || second_reference->rgba[4 * i + 3] >= coverage);
  if (erode > 0) compared = erode_mask(compared, image.width, image.height, erode);
  for (std::size_t i = 0; i < n; ++i) {
    const float* a = image.rgba.data() + 4 * i;
    const float* r = reference.rgba.data() + 4 * i;
    const float* r2 = second_reference ? second_reference->rgba.data() + 4 * i : r;
    if (!compared[i]) continue;
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(a[c]) || !std::isfinite(r[c]) || !std::isfinite(r2[c]))
        throw std::invalid_argument("pixel " + std::to_string(i % image.width) + ", " +
                                    std::to_string(i / image.width) + " is not finite");
      const double d = double(a[c]) - double(r[c]);
      const double noise = double(r[c]) - double(r2[c]);
      noise_squared += noise * noise;
      squared += d * d;
      reference_squared += double(r[c]) * double(r[c]);
      absolute += std::abs(d);
      e.max_abs = std::max(e.max_abs, std::abs(d));
    }
    ++e.pixels;
  }
  if (e.pixels == 0)
    throw std::invalid_argument(erode > 0 ? "no pixel is covered in both images " +
                                                std::to_string(erode) + " pixels inside the outline"
                                          : std::string("no pixel is covered in both images "
                                                        "(alpha below coverage)"));
  const double values = 3.0 * double(e.pixels);
  e.rmse = std::sqrt(squared / values);
  e.mean_abs = absolute / values;
  const double reference_rms = std::sqrt(reference_squared / values);
  e.relative_rmse = reference_rms > 0 ? e.rmse / reference_rms : 0.0;
  if (second_reference) {
    const double variance = noise_squared / values / 2;
    e.reference_noise = reference_rms > 0 ? std::sqrt(variance) / reference_rms : 0.0;
    e.corrected_relative_rmse =
        reference_rms > 0 ? std::sqrt(std::max(0.0, squared / values - variance)) / reference_rms
                          : 0.0;
  }
  return e;
}

}  // namespace render
