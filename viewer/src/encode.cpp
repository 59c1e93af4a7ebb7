#include "viewer/encode.h"

#include <turbojpeg.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

namespace viewer {
namespace {

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

}  // namespace viewer
