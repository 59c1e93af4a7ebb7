// The exact 8-bit tone map without a pow per channel; see render/image.h.
#include "render/image.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

namespace render {
namespace {

std::uint8_t code_of(float c) {
  return std::uint8_t(std::lround(255.f * tone_map(c, 0.0)));
}

// The tone map is monotonic in the exposed value c, so its 8-bit result is the number of
// thresholds at or below c: threshold k is the smallest float whose code is >= k. Found by
// bisection over float bit patterns (ordered like the values for c >= 0), so the table gives
// exactly lround(255 * tone_map) with a 255-entry search instead of a pow per channel.
const std::array<float, 255>& code_thresholds() {
  static const std::array<float, 255> thresholds = [] {
    std::array<float, 255> t{};
    for (int k = 1; k <= 255; ++k) {
      std::uint32_t lo = 0, hi = std::bit_cast<std::uint32_t>(1e6f);
      while (lo < hi) {
        const std::uint32_t mid = lo + (hi - lo) / 2;
        if (code_of(std::bit_cast<float>(mid)) >= k)
          hi = mid;
        else
          lo = mid + 1;
      }
      t[k - 1] = std::bit_cast<float>(lo);
    }
    return t;
  }();
  return thresholds;
}

// A first guess per bucket of floats (the top 18 bits: exponent and 10 mantissa bits): the
// code at the bucket's start, which no value in the bucket is below. A value then only steps
// past the few thresholds inside its bucket, so the result is still exact, at a table load
// and a branch that is almost always not taken instead of a binary search.
constexpr int kBucketShift = 13;
const std::vector<std::uint8_t>& bucket_codes() {
  static const std::vector<std::uint8_t> codes = [] {
    const std::array<float, 255>& t = code_thresholds();
    std::vector<std::uint8_t> c(std::size_t(1) << (31 - kBucketShift));
    for (std::size_t k = 0; k < c.size(); ++k) {
      const float start = std::bit_cast<float>(std::uint32_t(k << kBucketShift));
      c[k] = std::isnan(start)
                 ? 0
                 : std::uint8_t(std::upper_bound(t.begin(), t.end(), start) - t.begin());
    }
    return c;
  }();
  return codes;
}

}  // namespace

std::vector<std::uint8_t> tone_map_rgb8(const Image& image, double exposure) {
  const std::array<float, 255>& t = code_thresholds();
  const std::vector<std::uint8_t>& guess = bucket_codes();
  const std::size_t pixels = std::size_t(image.width) * std::size_t(image.height);
  std::vector<std::uint8_t> rgb(pixels * 3);
  const double scale = std::exp2(exposure);
  for (std::size_t p = 0; p < pixels; ++p)
    for (int c = 0; c < 3; ++c) {
      // As tone_map: exposure applied in double, negatives (and NaN) to 0.
      const float x = std::max(0.f, float(double(image.rgba[p * 4 + c]) * scale));
      unsigned code = guess[std::bit_cast<std::uint32_t>(x) >> kBucketShift];
      while (code < 255 && x >= t[code]) ++code;
      rgb[p * 3 + c] = std::uint8_t(code);
    }
  return rgb;
}

}  // namespace render
