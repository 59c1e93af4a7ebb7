#include "render/image.h"

#include "common/atomic_file.h"
#include "common/output_path.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <system_error>

namespace render {

namespace {

namespace fs = std::filesystem;

// Writes through OpenImageIO to a hidden temporary name with the target's extension (OIIO
// picks the format from it), then renames; the temporary is removed on any failure.
void write_atomically(const fs::path& path, const OIIO::ImageSpec& spec, const void* data,
                      const char* what, OIIO::TypeDesc data_type) {
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  if (!fs::is_directory(dir))
    throw ImageError(std::string("cannot write ") + what + " " + path.string() + ": directory " +
                     dir.string() + " does not exist; create it first");
  // Named like AtomicFile's temporaries (with the pid), so a killed run's are swept.
  const fs::path temp = common::temporary_path(path, /*keep_extension=*/true);
  auto fail = [&](const std::string& why) {
    std::error_code ec;
    fs::remove(temp, ec);
    throw ImageError(std::string("cannot write ") + what + " " + path.string() + ": " + why);
  };
  auto out = OIIO::ImageOutput::create(temp.string());
  if (!out) fail("no OpenImageIO writer for extension '" + path.extension().string() + "'");
  if (!out->open(temp.string(), spec)) fail(out->geterror());
  if (!out->write_image(data_type, data)) fail(out->geterror());
  if (!out->close()) fail(out->geterror());
  if (const std::string problem = common::output_target_problem(path); !problem.empty())
    fail(problem + "; write to another path");
  std::error_code ec;
  fs::rename(temp, path, ec);
  if (ec) fail("rename failed: " + ec.message());
}

float srgb_encode(float v) {
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

}  // namespace

float Image::max_rgb() const {
  float m = 0.f;
  for (std::size_t i = 0; i < rgba.size(); i += 4)
    for (int c = 0; c < 3; ++c) m = std::max(m, std::abs(rgba[i + c]));
  return m;
}

float tone_map(float linear, double exposure) {
  const float c = std::max(0.f, float(double(linear) * std::exp2(exposure)));
  const float f = c * (2.51f * c + 0.03f) / (c * (2.43f * c + 0.59f) + 0.14f);
  return srgb_encode(std::clamp(f, 0.f, 1.f));
}

void write_exr(const std::filesystem::path& path, const Image& image, ExrPixels pixels) {
  if (image.width < 1 || image.height < 1 ||
      image.rgba.size() != std::size_t(image.width) * image.height * 4)
    throw ImageError("cannot write " + path.string() + ": the image is empty or mis-sized");
  const bool half = pixels == ExrPixels::kHalf;
  OIIO::ImageSpec spec(image.width, image.height, 4,
                       half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"R", "G", "B", "A"};
  spec.alpha_channel = 3;
  spec.attribute("compression", half ? "piz" : "zip");
  write_atomically(path, spec, image.rgba.data(), "EXR", OIIO::TypeDesc::FLOAT);
}

void write_png(const std::filesystem::path& path, const Image& image, double exposure) {
  if (image.width < 1 || image.height < 1 ||
      image.rgba.size() != std::size_t(image.width) * image.height * 4)
    throw ImageError("cannot write " + path.string() + ": the image is empty or mis-sized");
  write_rgb8_png(path, image.width, image.height, tone_map_rgb8(image, exposure));
}

void write_rgb8_png(const std::filesystem::path& path, int width, int height,
                    const std::vector<std::uint8_t>& rgb, const char* what) {
  if (width < 1 || height < 1 || rgb.size() != std::size_t(width) * std::size_t(height) * 3)
    throw ImageError(std::string("cannot write ") + what + " " + path.string() +
                     ": the image is empty or mis-sized");
  OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
  spec.attribute("png:compressionLevel", 1);
  write_atomically(path, spec, rgb.data(), what, OIIO::TypeDesc::UINT8);
}

Image read_image(const std::filesystem::path& path) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in)
    throw ImageError("cannot read image " + path.string() + ": " + OIIO::geterror() +
                     " (check the path and that it is an image file)");
  const OIIO::ImageSpec& spec = in->spec();
  Image image;
  image.width = spec.width;
  image.height = spec.height;
  std::vector<float> all(std::size_t(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
    throw ImageError("cannot read image " + path.string() + ": " + in->geterror());
  image.rgba.assign(std::size_t(spec.width) * spec.height * 4, 1.f);
  for (std::size_t p = 0; p < std::size_t(spec.width) * spec.height; ++p)
    for (int c = 0; c < std::min(4, spec.nchannels); ++c)
      image.rgba[p * 4 + c] = all[p * spec.nchannels + c];
  return image;
}

}  // namespace render
