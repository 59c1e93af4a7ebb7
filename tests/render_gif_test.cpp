// The GIF writer, checked by an independent decoder: OpenImageIO reads the files back
// through giflib. Frames with at most 256 colours come back exactly, including noise that
// fills and clears the LZW table many times; richer frames come back close to their source.
#include "render/gif.h"

#include "test_support.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <stdexcept>
#include <vector>

namespace {

namespace fs = std::filesystem;
using render::Rgb8Image;
using test_support::scratch;

std::vector<Rgb8Image> read_gif(const fs::path& path) {
  auto in = OIIO::ImageInput::open(path.string());
  EXPECT_TRUE(in) << OIIO::geterror();
  std::vector<Rgb8Image> frames;
  if (!in) return frames;
  for (int s = 0; in->seek_subimage(s, 0); ++s) {
    const OIIO::ImageSpec& spec = in->spec();
    Rgb8Image f{spec.width, spec.height, {}};
    f.rgb.resize(std::size_t(spec.width) * std::size_t(spec.height) * 3);
    EXPECT_TRUE(in->read_image(s, 0, 0, 3, OIIO::TypeDesc::UINT8, f.rgb.data())) << in->geterror();
    frames.push_back(std::move(f));
  }
  return frames;
}

// Frames whose pixels are drawn from `palette_size` random colours.
std::vector<Rgb8Image> noise_frames(int frames, int width, int height, int palette_size,
                                    unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  std::vector<std::array<std::uint8_t, 3>> colours(static_cast<std::size_t>(palette_size));
  for (auto& c : colours)
    c = {std::uint8_t(byte(rng)), std::uint8_t(byte(rng)), std::uint8_t(byte(rng))};
  std::uniform_int_distribution<int> pick(0, palette_size - 1);
  std::vector<Rgb8Image> out;
  for (int f = 0; f < frames; ++f) {
    Rgb8Image image{width, height, {}};
    for (int i = 0; i < width * height; ++i) {
      const auto& c = colours[std::size_t(pick(rng))];
      image.rgb.insert(image.rgb.end(), c.begin(), c.end());
    }
    out.push_back(std::move(image));
  }
  return out;
}

TEST(Gif, FewColoursComeBackExactlyThroughGiflib) {
  // 256, 200, 3 and 1 colours: 8-, 8-, 2- and the minimum 2-bit code sizes.
  for (int colours : {256, 200, 3, 1}) {
    SCOPED_TRACE("colours " + std::to_string(colours));
    // Random colours may share a 5-bit bin; the palette then merges them, so pick colours
    // from distinct bins by construction: the test's palette is on a coarse grid.
    std::vector<Rgb8Image> frames = noise_frames(3, 97, 61, colours, unsigned(colours));
    for (auto& f : frames)
      for (auto& v : f.rgb) v = std::uint8_t(v & 0xf8);
    // Distinct grid colours may still number fewer than asked; all that matters is <= 256.
    const fs::path path = scratch("gif", "exact_" + std::to_string(colours) + ".gif");
    render::write_gif(path, frames, 24);
    const std::vector<Rgb8Image> back = read_gif(path);
    ASSERT_EQ(back.size(), frames.size());
    for (std::size_t i = 0; i < frames.size(); ++i) {
      EXPECT_EQ(back[i].width, 97);
      EXPECT_EQ(back[i].height, 61);
      EXPECT_EQ(back[i].rgb, frames[i].rgb) << "frame " << i;
    }
  }
}

TEST(Gif, LongRunsAndFullTablesDecode) {
  // One colour for a whole large frame builds ever longer strings; the noise frame after it
  // fills the 4096-code table again and again.
  Rgb8Image flat{640, 480, std::vector<std::uint8_t>(640 * 480 * 3, 0)};
  for (std::size_t i = 0; i < flat.rgb.size(); i += 3) flat.rgb[i] = 200;
  std::vector<Rgb8Image> frames{flat, noise_frames(1, 640, 480, 255, 7)[0]};  // 256 in all
  for (auto& v : frames[1].rgb) v = std::uint8_t(v & 0xf8);
  const fs::path path = scratch("gif", "runs.gif");
  render::write_gif(path, frames, 10);
  const std::vector<Rgb8Image> back = read_gif(path);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].rgb, frames[0].rgb);
  EXPECT_EQ(back[1].rgb, frames[1].rgb);
}

TEST(Gif, ManyColoursAreCloseAfterMedianCut) {
  // A smooth two-axis gradient with about 16 k distinct colours.
  Rgb8Image g{256, 256, {}};
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x)
      g.rgb.insert(g.rgb.end(), {std::uint8_t(x), std::uint8_t(y), std::uint8_t((x + y) / 2)});
  const fs::path path = scratch("gif", "gradient.gif");
  render::write_gif(path, {g}, 24);
  const std::vector<Rgb8Image> back = read_gif(path);
  ASSERT_EQ(back.size(), 1u);
  double sum = 0;
  int worst = 0;
  for (std::size_t i = 0; i < g.rgb.size(); ++i) {
    const int d = std::abs(int(back[0].rgb[i]) - int(g.rgb[i]));
    sum += d;
    worst = std::max(worst, d);
  }
  // 256 boxes over a 256 x 256 square: about 16 x 16 levels each, so a pixel is within half
  // a box side of its entry in the two varying channels.
  EXPECT_LT(sum / double(g.rgb.size()), 6.0);
  EXPECT_LE(worst, 24);
}

TEST(Gif, PaletteMapsEachPixelToItsBox) {
  const std::vector<Rgb8Image> frames = noise_frames(2, 50, 40, 1000, 3);
  const render::GifPalette p = render::median_cut_palette(frames, 16);
  ASSERT_EQ(p.colours.size(), 16u);
  ASSERT_EQ(p.lookup.size(), 32768u);
  // Every palette entry is used by some pixel: the boxes partition the occupied bins.
  std::vector<bool> used(16, false);
  for (const Rgb8Image& f : frames)
    for (std::size_t i = 0; i < f.rgb.size(); i += 3) used[p.index(&f.rgb[i])] = true;
  for (int i = 0; i < 16; ++i) EXPECT_TRUE(used[std::size_t(i)]) << "entry " << i;
}

TEST(Gif, RefusesWhatItCannotWrite) {
  const fs::path path = scratch("gif", "bad.gif");
  EXPECT_THROW(render::write_gif(path, {}, 24), std::invalid_argument);
  Rgb8Image a{4, 4, std::vector<std::uint8_t>(48, 0)}, b{4, 5, std::vector<std::uint8_t>(60, 0)};
  EXPECT_THROW(render::write_gif(path, {a, b}, 24), std::invalid_argument);
  EXPECT_THROW(render::write_gif(path, {a}, 0), std::invalid_argument);
  Rgb8Image short_data{4, 4, std::vector<std::uint8_t>(47, 0)};
  EXPECT_THROW(render::write_gif(path, {short_data}, 24), std::invalid_argument);
  EXPECT_THROW(render::median_cut_palette({a}, 0), std::invalid_argument);
  const std::vector<std::uint8_t> past{0, 1, 4};
  EXPECT_THROW(render::gif_lzw(past, 2), std::invalid_argument);
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
