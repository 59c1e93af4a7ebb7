#include "view_encode.h"

#include <turbojpeg.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <memory>
#include <string>

namespace prtr_app {
namespace {

std::uint8_t code_of(float c) {
  return std::uint8_t(std::lround(255.f * render::tone_map(c, 0.0)));
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

struct TjHandle {
  tjhandle handle;
  explicit TjHandle(tjhandle h) : handle(h) {
    if (!handle) throw JpegError("libjpeg-turbo: cannot create a handle");
  }
  ~TjHandle() { tjDestroy(handle); }
  TjHandle(const TjHandle&) = delete;
  TjHandle& operator=(const TjHandle&) = delete;
};

}  // namespace

std::vector<std::uint8_t> tone_map_rgb8(const render::Image& image, double exposure) {
  const std::array<float, 255>& t = code_thresholds();
  const std::vector<std::uint8_t>& guess = bucket_codes();
  const std::size_t pixels = std::size_t(image.width) * std::size_t(image.height);
  std::vector<std::uint8_t> rgb(pixels * 3);
  const double scale = std::exp2(exposure);
  for (std::size_t p = 0; p < pixels; ++p)
    for (int c = 0; c < 3; ++c) {
      // As render::tone_map: exposure applied in double, negatives (and NaN) to 0.
      const float x = std::max(0.f, float(double(image.rgba[p * 4 + c]) * scale));
      unsigned code = guess[std::bit_cast<std::uint32_t>(x) >> kBucketShift];
      while (code < 255 && x >= t[code]) ++code;
      rgb[p * 3 + c] = std::uint8_t(code);
    }
  return rgb;
}

void composite_overlay(std::vector<std::uint8_t>& rgb, int width, int height,
                       const render::Picture& overlay, double opacity) {
  if (overlay.width != width || overlay.height != height ||
      rgb.size() != std::size_t(width) * std::size_t(height) * 3)
    throw std::invalid_argument("composite_overlay: the overlay is not the frame's size");
  const float a = float(std::clamp(opacity, 0.0, 1.0));
  for (std::size_t p = 0; p < rgb.size(); p += 3) {
    const std::uint8_t* o = overlay.rgb.data() + p;
    if (o[0] == kOverlayTransparent[0] && o[1] == kOverlayTransparent[1] &&
        o[2] == kOverlayTransparent[2])
      continue;
    for (int c = 0; c < 3; ++c)
      rgb[p + c] = std::uint8_t(std::lround(a * float(o[c]) + (1.f - a) * float(rgb[p + c])));
  }
}

std::vector<std::uint8_t> encode_jpeg(const std::vector<std::uint8_t>& rgb, int width, int height,
                                      int quality) {
  if (width < 1 || height < 1 || rgb.size() != std::size_t(width) * std::size_t(height) * 3)
    throw std::invalid_argument("encode_jpeg: the RGB buffer does not match its size");
  TjHandle tj(tjInitCompress());
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  const int rc = tjCompress2(tj.handle, rgb.data(), width, 0, height, TJPF_RGB, &buffer, &size,
                             TJSAMP_420, std::clamp(quality, 1, 100), TJFLAG_FASTDCT);
  const std::unique_ptr<unsigned char, void (*)(unsigned char*)> owned(buffer, tjFree);
  if (rc != 0) throw JpegError(std::string("libjpeg-turbo: ") + tjGetErrorStr2(tj.handle));
  return std::vector<std::uint8_t>(buffer, buffer + size);
}

std::vector<std::uint8_t> decode_jpeg(const std::vector<std::uint8_t>& jpeg, int& width,
                                      int& height) {
  TjHandle tj(tjInitDecompress());
  int subsampling = 0, colourspace = 0;
  if (tjDecompressHeader3(tj.handle, jpeg.data(), jpeg.size(), &width, &height, &subsampling,
                          &colourspace) != 0)
    throw JpegError(std::string("libjpeg-turbo: ") + tjGetErrorStr2(tj.handle));
  std::vector<std::uint8_t> rgb(std::size_t(width) * std::size_t(height) * 3);
  if (tjDecompress2(tj.handle, jpeg.data(), jpeg.size(), rgb.data(), width, 0, height, TJPF_RGB,
                    0) != 0)
    throw JpegError(std::string("libjpeg-turbo: ") + tjGetErrorStr2(tj.handle));
  return rgb;
}

}  // namespace prtr_app
