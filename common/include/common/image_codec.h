// common/image_codec.h: how prtr reads and writes image files (probes, EXR/PNG outputs, text
// on pictures). OpenImageIO does the work, but only behind this interface: the libraries call
// image_codec(), and each executable decides how that is bound. Tests, benchmarks and fuzz
// targets link OpenImageIO in (the prtr_oiio_codec objects); the prtr command loads it on
// first use from a module beside the binary (image_codec_loader.cpp), because OpenImageIO
// brings some 260 shared libraries whose loading and relocation was most of the start-up
// time of every prtr command, including the many that never touch an image (docs/
// ARCHITECTURE.md, "Image files").
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace common {

// The image module could not be loaded: what was tried and how to fix it.
class ImageCodecError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What a file's header says, for the checks loaders make before sizing anything from it.
struct ImageHeader {
  int width = 0, height = 0, channels = 0;
  int depth = 1;      // > 1: a volume
  bool deep = false;  // deep (multi-sample) pixels
  // The pixels' window and the display window (OpenEXR's data and display windows).
  int x = 0, y = 0, full_x = 0, full_y = 0, full_width = 0, full_height = 0;
  bool floating_point = false;  // pixels stored as floats (EXR, HDR) rather than integers
  std::string color_space{};    // the colour space the file names ("" when none)
  float gamma = 1.0f;           // its gamma, when the colour space is a gamma curve
  std::string format{};         // the reader's format name ("openexr", "hdr", "png", ...)
};

// An image file opened for reading.
class ImageFile {
 public:
  virtual ~ImageFile() = default;
  virtual const ImageHeader& header() const = 0;
  // The first `channels` channels of every pixel as float, row-major, into `pixels` (width x
  // height x channels). False, with *error set, when the pixels cannot be decoded.
  virtual bool read(int channels, float* pixels, std::string* error) = 0;
};

enum class StoredPixels { kUint8, kHalf, kFloat };

struct ImageWriteSpec {
  int width = 0, height = 0, channels = 0;
  StoredPixels stored = StoredPixels::kFloat;  // what the file holds
  std::vector<std::string> channel_names{};    // empty: the format's defaults
  int alpha_channel = -1;
  std::string compression{};  // e.g. "zip", "piz" for EXR ("": the format's default)
  int png_compression_level = -1;
};

class ImageCodec {
 public:
  virtual ~ImageCodec() = default;
  // Null, with *error set, when `path` cannot be opened as an image. May throw
  // std::bad_alloc when a header asks for more memory than there is.
  virtual std::unique_ptr<ImageFile> open(const std::string& path, std::string* error) const = 0;
  // Writes `pixels` (uint8 when spec.stored is kUint8, float otherwise, interleaved) to
  // `path` in the format its extension names. False, with *error set, on failure.
  virtual bool write(const std::string& path, const ImageWriteSpec& spec, const void* pixels,
                     std::string* error) const = 0;
  // Draws `text` into an 8-bit RGB picture with its baseline's left end at (x, y), `size`
  // pixels high; false when no font could be found.
  virtual bool draw_text(std::uint8_t* rgb, int width, int height, int x, int y,
                         const std::string& text, int size, const float colour[3]) const = 0;
};

// The codec this executable is bound to. Throws ImageCodecError when it is loaded on first
// use and the module is missing or does not match.
const ImageCodec& image_codec();

// The module's entry point (image_codec_module.cpp): the interface version it was built with,
// and its codec. A module from another build of prtr is refused rather than trusted.
inline constexpr std::uint32_t kImageCodecInterface = 1;
struct ImageCodecEntry {
  std::uint32_t interface_version;
  const ImageCodec* codec;
};
inline constexpr const char* kImageCodecEntryName = "prtr_image_codec_entry";

}  // namespace common
