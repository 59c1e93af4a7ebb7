#include "difference.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace viewer::detail {

namespace {

float luminance(const float* p) {
  return 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
}

// A vertical bar of the ramp with its ends labelled, at the top-left corner.
void draw_scale(render::Picture& picture, double full_scale) {
  const int height = std::min(120, picture.height / 2), width = 10, x0 = 6, y0 = 6;
  if (height < 20 || picture.width < 60) return;
  // An opaque backing: text is anti-aliased against what lies under it, and the transparent
  // key colour must not bleed into its edges.
  render::fill_rect(picture, {x0 - 4, y0 - 4, x0 + width + 44, y0 + height + 6}, {30, 30, 30});
  for (int y = 0; y < height; ++y) {
    const render::Colour8 c = difference_colour(1.0 - double(y) / (height - 1));
    render::fill_rect(picture, {x0, y0 + y, x0 + width, y0 + y + 1}, c);
  }
  char top[32];
  std::snprintf(top, sizeof top, "%g %%", 100.0 * full_scale);
  const render::Colour8 ink{255, 255, 255};
  render::draw_text(picture, x0 + width + 4, y0 + 10, top, 11, ink);
  render::draw_text(picture, x0 + width + 4, y0 + height, "0", 11, ink);
}

}  // namespace

render::Colour8 difference_colour(double t) {
  static constexpr std::array<std::array<double, 3>, 5> kStops{
      {{20, 30, 110}, {40, 190, 230}, {60, 200, 80}, {250, 220, 40}, {220, 30, 30}}};
  t = std::clamp(std::isfinite(t) ? t : 1.0, 0.0, 1.0) * double(kStops.size() - 1);
  const std::size_t i = std::min(std::size_t(t), kStops.size() - 2);
  const double f = t - double(i);
  render::Colour8 c;
  for (int k = 0; k < 3; ++k)
    c[std::size_t(k)] = std::uint8_t(
        std::lround(kStops[i][std::size_t(k)] * (1 - f) + kStops[i + 1][std::size_t(k)] * f));
  return c;
}

render::Picture difference_picture(const render::Image& test, const render::Image& reference,
                                   double full_scale, const render::Colour8& transparent,
                                   DifferenceStats* stats) {
  if (test.width != reference.width || test.height != reference.height ||
      test.rgba.size() != reference.rgba.size())
    throw std::invalid_argument("difference_picture: the two frames differ in size");
  const std::size_t pixels = std::size_t(test.width) * std::size_t(test.height);
  const auto covered = [&](std::size_t p) {
    return test.rgba[4 * p + 3] > 0.f || reference.rgba[4 * p + 3] > 0.f;
  };
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t p = 0; p < pixels; ++p)
    if (covered(p)) {
      sum += luminance(&reference.rgba[4 * p]);
      ++count;
    }
  const double floor = std::max(1e-6, 0.01 * (count > 0 ? sum / double(count) : 0.0));
  render::Picture picture(test.width, test.height, transparent);
  double squares = 0, largest = 0;
  for (std::size_t p = 0; p < pixels; ++p) {
    if (!covered(p)) continue;
    const double u = luminance(&reference.rgba[4 * p]);
    const double e = std::abs(double(luminance(&test.rgba[4 * p])) - u) / std::max(u, floor);
    squares += e * e;
    largest = std::max(largest, e);
    const render::Colour8 c = difference_colour(e / full_scale);
    std::copy(c.begin(), c.end(), picture.rgb.begin() + std::ptrdiff_t(3 * p));
  }
  draw_scale(picture, full_scale);
  if (stats != nullptr) *stats = {count > 0 ? std::sqrt(squares / double(count)) : 0.0, largest};
  return picture;
}

}  // namespace viewer::detail
