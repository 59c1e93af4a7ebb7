// viewer/encode.h: a rendered frame to the JPEG `prtr view` sends: the tone map of
// render/image.h (exposure, Narkowicz's ACES fit, sRGB, 8 bits), an optional false-colour
// overlay blended over the mesh, then libjpeg-turbo. libjpeg-turbo stays inside
// view_encode.cpp.
#pragma once

#include "render/false_colour.h"
#include "render/image.h"

#include <cstdint>
#include <stdexcept>
#include <vector>

namespace viewer {

// The colour overlay pictures are drawn on where nothing is: composite_overlay leaves those
// pixels alone.
inline constexpr render::Colour8 kOverlayTransparent{255, 0, 255};

// Mixes `overlay` (same size) into `rgb` with weight `opacity` wherever the overlay is not
// kOverlayTransparent. Throws std::invalid_argument on a size mismatch.
void composite_overlay(std::vector<std::uint8_t>& rgb, int width, int height,
                       const render::Picture& overlay, double opacity);

class JpegError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Baseline JPEG of an RGB8 image (4:2:0, `quality` 1..100).
std::vector<std::uint8_t> encode_jpeg(const std::vector<std::uint8_t>& rgb, int width, int height,
                                      int quality = 85);

// Decodes a JPEG to RGB8 (for tests): width and height out.
std::vector<std::uint8_t> decode_jpeg(const std::vector<std::uint8_t>& jpeg, int& width,
                                      int& height);

}  // namespace viewer
