#include "oiio_codec.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

namespace common {

namespace {

class OiioFile final : public ImageFile {
 public:
  explicit OiioFile(std::unique_ptr<OIIO::ImageInput> in) : in_(std::move(in)) {
    const OIIO::ImageSpec& spec = in_->spec();
    header_.width = spec.width;
    header_.height = spec.height;
    header_.channels = spec.nchannels;
    header_.depth = spec.depth;
    header_.deep = spec.deep;
    header_.x = spec.x;
    header_.y = spec.y;
    header_.full_x = spec.full_x;
    header_.full_y = spec.full_y;
    header_.full_width = spec.full_width;
    header_.full_height = spec.full_height;
    header_.floating_point = spec.format.is_floating_point();
    header_.color_space = spec.get_string_attribute("oiio:ColorSpace");
    header_.gamma = spec.get_float_attribute("oiio:Gamma", 1.0f);
    header_.format = in_->format_name();
  }
  ~OiioFile() override { in_->close(); }

  const ImageHeader& header() const override { return header_; }

  bool read(int channels, float* pixels, std::string* error) override {
    if (in_->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels)) return true;
    *error = in_->geterror();
    return false;
  }

 private:
  std::unique_ptr<OIIO::ImageInput> in_;
  ImageHeader header_;
};

OIIO::TypeDesc type_of(StoredPixels stored) {
  switch (stored) {
    case StoredPixels::kUint8:
      return OIIO::TypeDesc::UINT8;
    case StoredPixels::kHalf:
      return OIIO::TypeDesc::HALF;
    case StoredPixels::kFloat:
      break;
  }
  return OIIO::TypeDesc::FLOAT;
}

class OiioCodec final : public ImageCodec {
 public:
  std::unique_ptr<ImageFile> open(const std::string& path, std::string* error) const override {
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
      *error = OIIO::geterror();
      return nullptr;
    }
    return std::make_unique<OiioFile>(std::move(in));
  }

  bool write(const std::string& path, const ImageWriteSpec& s, const void* pixels,
             std::string* error) const override {
    OIIO::ImageSpec spec(s.width, s.height, s.channels, type_of(s.stored));
    if (!s.channel_names.empty()) spec.channelnames = s.channel_names;
    spec.alpha_channel = s.alpha_channel;
    if (!s.compression.empty()) spec.attribute("compression", s.compression);
    if (s.png_compression_level >= 0)
      spec.attribute("png:compressionLevel", s.png_compression_level);
    auto out = OIIO::ImageOutput::create(path);
    if (!out) {
      *error = "no OpenImageIO writer for " + path;
      return false;
    }
    const OIIO::TypeDesc given =
        s.stored == StoredPixels::kUint8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT;
    if (!out->open(path, spec) || !out->write_image(given, pixels) || !out->close()) {
      *error = out->geterror();
      return false;
    }
    return true;
  }

  bool draw_text(std::uint8_t* rgb, int width, int height, int x, int y, const std::string& text,
                 int size, const float colour[3]) const override {
    OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
    OIIO::ImageBuf buffer(spec, rgb);  // wraps the caller's pixels
    // DejaVu Sans first (Debian's fonts-dejavu-core), then OpenImageIO's own default.
    return OIIO::ImageBufAlgo::render_text(buffer, x, y, text, size, "DejaVuSans", colour) ||
           OIIO::ImageBufAlgo::render_text(buffer, x, y, text, size, "", colour);
  }
};

}  // namespace

const ImageCodec& oiio_image_codec() {
  static const OiioCodec codec;
  return codec;
}

}  // namespace common
