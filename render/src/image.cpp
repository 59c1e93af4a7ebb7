#include "render/image.h"

#include "common/atomic_file.h"
#include "common/image_codec.h"
#include "common/output_path.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <system_error>

namespace render {

namespace {

namespace fs = std::filesystem;

// Writes through the image codec to a hidden temporary name with the target's extension
// (which picks the format), then renames; the temporary is removed on any failure.
void write_atomically(const fs::path& path, const common::ImageWriteSpec& spec, const void* data,
                      const char* what) {
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
  std::string error;
  if (!common::image_codec().write(temp.string(), spec, data, &error)) fail(error);
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
  common::ImageWriteSpec spec;
  spec.width = image.width;
  spec.height = image.height;
  spec.channels = 4;
  spec.stored = half ? common::StoredPixels::kHalf : common::StoredPixels::kFloat;
  spec.channel_names = {"R", "G", "B", "A"};
  spec.alpha_channel = 3;
  spec.compression = half ? "piz" : "zip";
  write_atomically(path, spec, image.rgba.data(), "EXR");
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
  common::ImageWriteSpec spec;
  spec.width = width;
  spec.height = height;
  spec.channels = 3;
  spec.stored = common::StoredPixels::kUint8;
  spec.png_compression_level = 1;
  write_atomically(path, spec, rgb.data(), what);
}

Image read_image(const std::filesystem::path& path) {
  std::string error;
  const auto in = common::image_codec().open(path.string(), &error);
  if (!in)
    throw ImageError("cannot read image " + path.string() + ": " + error +
                     " (check the path and that it is an image file)");
  const common::ImageHeader& spec = in->header();
  Image image;
  image.width = spec.width;
  image.height = spec.height;
  std::vector<float> all(std::size_t(spec.width) * spec.height * spec.channels);
  if (!in->read(spec.channels, all.data(), &error))
    throw ImageError("cannot read image " + path.string() + ": " + error);
  image.rgba.assign(std::size_t(spec.width) * spec.height * 4, 1.f);
  for (std::size_t p = 0; p < std::size_t(spec.width) * spec.height; ++p)
    for (int c = 0; c < std::min(4, spec.channels); ++c)
      image.rgba[p * 4 + c] = all[p * spec.channels + c];
  return image;
}

}  // namespace render
