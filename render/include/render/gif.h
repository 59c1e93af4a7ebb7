// render/gif.h: animated GIF previews (GIF89a) written without an image library.
//
// Every frame shares one global palette: the median cut of P. Heckbert ("Color image
// quantization for frame buffer display", SIGGRAPH 1982) over a histogram of all frames at 5
// bits per channel. One palette for the whole sequence keeps an animation free of the
// flicker that per-frame palettes give a rotating environment, and lets the palette be
// chosen once. Pixel data is LZW-coded as the GIF89a specification (CompuServe, 1990)
// defines it: variable-width codes from min_code_size + 1 bits up to 12, a clear code when
// the table is full, packed least-significant bit first, in sub-blocks of at most 255 bytes.
// The NETSCAPE2.0 application extension makes viewers loop.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

namespace render {

// 8-bit sRGB pixels, RGB, row 0 first.
struct Rgb8Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // width * height * 3
};

struct GifPalette {
  std::vector<std::array<std::uint8_t, 3>> colours;  // at most 256
  // The palette index of every colour at 5 bits per channel ((r >> 3) << 10 | (g >> 3) << 5
  // | b >> 3): the nearest palette colour in RGB distance.
  std::vector<std::uint8_t> lookup;

  std::uint8_t index(const std::uint8_t* rgb) const {
    return lookup[std::size_t(rgb[0] >> 3) << 10 | std::size_t(rgb[1] >> 3) << 5 |
                  std::size_t(rgb[2] >> 3)];
  }
};

// A palette of at most `colours` (1..256) entries for all `frames` together.
GifPalette median_cut_palette(const std::vector<Rgb8Image>& frames, int colours = 256);

// The LZW code stream of `indices` (each below 2^min_code_size, min_code_size 2..8), packed
// into bytes, before it is cut into sub-blocks.
std::vector<std::uint8_t> gif_lzw(std::span<const std::uint8_t> indices, int min_code_size);

// The whole file: frames of one size, shown at `fps` (the delay is rounded to GIF's 1/100 s,
// at least 2, since browsers slow shorter delays down to 1/10 s), looping forever. Written
// atomically (common/atomic_file.h). Throws std::invalid_argument for an empty sequence,
// frames of different sizes or sizes past 65535, a rate that is not positive, and common::IoError
// when writing fails.
void write_gif(const std::filesystem::path& path, const std::vector<Rgb8Image>& frames, double fps);

}  // namespace render
