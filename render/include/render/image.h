// render/image.h: a float RGBA image and its EXR and PNG writers (OpenImageIO, only in
// render/src/image.cpp).
//
// Pixels are linear radiance in the probe's units (docs/ARCHITECTURE.md "Rendering", Output: tone
// mapping happens only when writing PNG); alpha is coverage (1 where the mesh is, 0 on the
// background). Row 0 is the top row. Both writers are atomic: a temporary file in the target's
// directory, renamed over the target once complete.
//
// PNG tone map, documented here once: c = radiance * 2^exposure, then the ACES filmic curve
// fitted by K. Narkowicz (2015), f(c) = c (2.51 c + 0.03) / (c (2.43 c + 0.59) + 0.14)
// clamped to [0, 1], then the sRGB transfer function, then 8 bits. Alpha is dropped: the
// PNG is a preview with its background.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace render {

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgba;  // width * height * 4, row-major from the top row

  float* pixel(int x, int y) { return rgba.data() + (std::size_t(y) * width + x) * 4; }
  const float* pixel(int x, int y) const { return rgba.data() + (std::size_t(y) * width + x) * 4; }
  // Largest |R|, |G| or |B| over the image (0 for an empty image).
  float max_rgb() const;
};

class ImageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Linear RGBA EXR (channels R, G, B, A; alpha is coverage): 32-bit float, ZIP compressed,
// or half float, PIZ compressed (OpenEXR's lossless wavelet coder, made for noisy half
// data: a 1280 x 948 frame writes in a fifth of the time and takes a quarter of the bytes;
// half keeps 11 significant bits up to 65504, what renderers write for frame sequences).
enum class ExrPixels { kFloat, kHalf };
void write_exr(const std::filesystem::path& path, const Image& image,
               ExrPixels pixels = ExrPixels::kFloat);

// 8-bit sRGB PNG after exposure and the tone map above. Deflate runs at level 1: a 1280 x 948
// frame writes in 63 ms instead of 280 ms at zlib's default, for a few percent more bytes.
void write_png(const std::filesystem::path& path, const Image& image, double exposure = 0.0);

// 8-bit RGB bytes (row 0 at the top) as a PNG, byte for byte, written atomically like every
// image here; `what` names the file in messages ("PNG", "picture").
void write_rgb8_png(const std::filesystem::path& path, int width, int height,
                    const std::vector<std::uint8_t>& rgb, const char* what = "PNG");

// The tone map above for one linear value, before quantisation (for tests and previews).
float tone_map(float linear, double exposure);

// The whole image through the tone map, 8 bits per channel, RGB, row 0 first: exactly
// lround(255 * tone_map) per channel, found in a threshold table instead of a pow per
// channel (write_png and prtr view's frames both use it).
std::vector<std::uint8_t> tone_map_rgb8(const Image& image, double exposure);

// Reads any image OpenImageIO understands into RGBA floats (missing alpha -> 1), for tests
// and comparisons.
Image read_image(const std::filesystem::path& path);

}  // namespace render
