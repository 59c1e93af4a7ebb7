// probes/load.cpp: the one seam to OpenImageIO for environment maps. Reads any format
// OpenImageIO reads, checks texels, and resamples angular ("light probe") maps to lat-long.
//
// Angular maps: P. Debevec, "Rendering synthetic objects into real scenes", SIGGRAPH 1998,
// and his Light Probe Image Gallery; the orientation used here is the one in probes/load.h.
#include "probes/load.h"

#include <OpenImageIO/imageio.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <new>
#include <numbers>
#include <sstream>
#include <system_error>
#include <unordered_map>
#include <utility>
#include <vector>

namespace probes {

namespace {

constexpr double kPi = std::numbers::pi;

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  throw ProbeError(path.string() + ": " + what);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

// --- Guards in front of OpenImageIO --------------------------------------------------------
// OpenImageIO and the libraries under it trust sizes written in the file: OpenEXR allocates
// an attribute's claimed size while reading the header, and every format's pixel buffer is
// sized from the header's width and height. Both are checked against the file's size first.

std::string gigabytes(double bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g GB", bytes / 1e9);
  return buf;
}

// The number of bytes OpenEXR reads for an attribute value of `type` starting at `at`, which
// for most types is fixed by the type and not by the size the file declares; -1 for types
// whose value is as long as the declared size (strings, vectors, unknown types), -2 when a
// value does not end within `limit`.
std::int64_t exr_value_bytes(const std::string& type, const std::vector<char>& bytes,
                             std::size_t at, std::size_t limit) {
  static const std::unordered_map<std::string, std::int64_t> kFixed = {
      {"box2i", 16},      {"box2f", 16},   {"chromaticities", 32},
      {"compression", 1}, {"double", 8},   {"envmap", 1},
      {"float", 4},       {"int", 4},      {"keycode", 28},
      {"lineOrder", 1},   {"m33f", 36},    {"m33d", 72},
      {"m44f", 64},       {"m44d", 128},   {"rational", 8},
      {"tiledesc", 9},    {"timecode", 8}, {"v2i", 8},
      {"v2f", 8},         {"v2d", 16},     {"v3i", 12},
      {"v3f", 12},        {"v3d", 24},     {"deepImageState", 1}};
  if (const auto it = kFixed.find(type); it != kFixed.end()) return it->second;
  if (type == "chlist") {
    // Channel records (name\0, then 16 bytes) up to an empty name.
    std::size_t pos = at;
    while (pos < limit && bytes[pos] != 0) {
      while (pos < limit && bytes[pos] != 0) ++pos;
      pos += 1 + 16;
    }
    return pos < limit ? std::int64_t(pos + 1 - at) : -2;
  }
  if (type == "preview") {
    // Width and height, then 4 bytes per pixel: the size of the buffer OpenEXR allocates.
    if (at + 8 > limit) return -2;
    std::uint32_t wh[2];
    std::memcpy(wh, bytes.data() + at, 8);
    return std::int64_t(8 + 4 * std::uint64_t(wh[0]) * wh[1]);
  }
  return -1;
}

// Walks the attribute list of an OpenEXR header (name\0 type\0 int32 size, value) and
// returns the first attribute whose size is negative, runs past the end of the file, or
// differs from what OpenEXR will read for its type (OpenEXR then reads the rest of the header
// from a different place than the sizes say, so a check by sizes alone would be blind); empty
// when every attribute is consistent. Multi-part files hold several headers, ended by an
// empty one.
std::string check_exr_header(const std::filesystem::path& path, std::uintmax_t file_size) {
  std::ifstream in(path, std::ios::binary);
  // Headers are small; what matters is that no attribute claims more than the file holds.
  constexpr std::size_t kHeaderWindow = 1 << 20;
  std::vector<char> bytes(std::min<std::uintmax_t>(file_size, kHeaderWindow));
  in.read(bytes.data(), std::streamsize(bytes.size()));
  bytes.resize(std::size_t(in.gcount()));
  if (bytes.size() < 8 || std::memcmp(bytes.data(), "\x76\x2f\x31\x01", 4) != 0) return {};
  std::uint32_t version = 0;
  std::memcpy(&version, bytes.data() + 4, 4);
  const bool multipart = (version & 0x1000u) != 0;
  std::size_t at = 8;
  // A null-terminated name of at most 255 characters at `at`, or empty when there is none.
  const auto name_at = [&](std::size_t& pos, std::string& name) {
    const std::size_t limit = std::min(bytes.size(), pos + 256);
    for (std::size_t i = pos; i < limit; ++i) {
      if (bytes[i] == 0) {
        name.assign(bytes.data() + pos, i - pos);
        pos = i + 1;
        return true;
      }
    }
    return false;
  };
  for (int header = 0; header < 1024; ++header) {
    bool any = false;
    while (true) {
      std::string name, type;
      if (!name_at(at, name)) return {};  // past what we read: OpenEXR reports it
      if (name.empty()) break;
      any = true;
      if (!name_at(at, type) || at + 4 > bytes.size()) return {};
      std::int32_t size = 0;
      std::memcpy(&size, bytes.data() + at, 4);
      at += 4;
      if (size < 0 || std::uintmax_t(size) > file_size - std::min<std::uintmax_t>(at, file_size)) {
        return "its OpenEXR header attribute '" + name + "' (" + type + ") claims " +
               std::to_string(size) + " bytes, but the file has only " + std::to_string(file_size) +
               " bytes in all; the file is damaged or truncated, re-export it";
      }
      if (std::size_t(size) > bytes.size() - at) return {};
      const std::int64_t takes = exr_value_bytes(type, bytes, at, bytes.size());
      if (takes != -1 && takes != size) {
        return "its OpenEXR header attribute '" + name + "' (" + type + ") declares " +
               std::to_string(size) + " bytes, but its value " +
               (takes == -2 ? std::string("does not end within the file")
                            : "takes " + std::to_string(takes)) +
               "; the file is damaged, re-export it";
      }
      at += std::size_t(size);
    }
    if (!multipart || !any) break;
  }
  return {};
}

// Bytes this loader allocates per texel: the float read buffer (up to three channels) and
// the Rgb array.
constexpr double kBytesPerTexel = 3 * sizeof(float) + sizeof(Rgb);
// The most texel bytes one byte of file can decode to. zlib (OpenEXR's ZIP, PXR24) peaks near
// 1032:1 on half-float data, which doubles as float, and our Rgb copy doubles it again; the
// factor covers that with room. A header claiming more than this is lying about its size.
constexpr double kMaxExpansion = 4096;
// Small images are never refused for their file size: tiny constant maps compress well.
constexpr double kAlwaysAllowedBytes = 64.0 * 1024 * 1024;

double available_memory() {
  const long pages = ::sysconf(_SC_AVPHYS_PAGES);
  const long page = ::sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? double(pages) * double(page) : 0.0;
}

// --- Colour encoding ---------------------------------------------------------------------
// OpenImageIO's read_image converts integer texels to [0, 1] floats but does not decode
// them: an 8-bit PNG holding 128 reads as 0.502, not as the 0.216 of linear radiance it
// encodes. The file's colour space (OpenImageIO reports it as "oiio:ColorSpace") says how.

enum class Encoding { kLinear, kSrgb, kGamma };

float srgb_to_linear(float c) {
  // IEC 61966-2-1.
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

Encoding encoding_of(const OIIO::ImageSpec& spec, float* gamma) {
  const std::string space = lower(spec.get_string_attribute("oiio:ColorSpace"));
  *gamma = spec.get_float_attribute("oiio:Gamma", 1.0f);
  if (space == "srgb") return Encoding::kSrgb;
  if (space.rfind("gammacorrected", 0) == 0) {
    if (*gamma == 1.0f) {  // OpenImageIO spells the exponent in the name, e.g. "2.2"
      const std::string number = space.substr(std::string("gammacorrected").size());
      *gamma = std::strtof(number.c_str(), nullptr);
    }
    return *gamma > 0.0f && *gamma != 1.0f ? Encoding::kGamma : Encoding::kLinear;
  }
  // No colour space named: integer images are display-encoded by convention (sRGB), float
  // images (EXR, HDR) hold linear radiance.
  if (space.empty() && !spec.format.is_floating_point()) return Encoding::kSrgb;
  return Encoding::kLinear;
}

// --- Angular -> lat-long -----------------------------------------------------------------

// Bilinear between pixel centres of an n x n image, clamped at the edges.
Rgb bilinear(const std::vector<Rgb>& image, int n, double px, double py) {
  const double fx = std::clamp(px - 0.5, 0.0, double(n - 1));
  const double fy = std::clamp(py - 0.5, 0.0, double(n - 1));
  const int x0 = std::min(int(fx), n - 1), y0 = std::min(int(fy), n - 1);
  const int x1 = std::min(x0 + 1, n - 1), y1 = std::min(y0 + 1, n - 1);
  const float tx = float(fx - x0), ty = float(fy - y0);
  auto at = [&](int x, int y) -> const Rgb& { return image[std::size_t(y) * n + x]; };
  const Rgb top = (1.0f - tx) * at(x0, y0) + tx * at(x1, y0);
  const Rgb bottom = (1.0f - tx) * at(x0, y1) + tx * at(x1, y1);
  return (1.0f - ty) * top + ty * bottom;
}

// Resamples an n x n angular map to a 2n x n lat-long map at the lat-long pixel centres.
std::vector<Rgb> angular_to_latlong(const std::vector<Rgb>& angular, int n) {
  const int width = 2 * n, height = n;
  std::vector<Rgb> out(std::size_t(width) * std::size_t(height));
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      for (int x = 0; x < width; ++x) {
        const Eigen::Vector3d d = latlong_direction((x + 0.5) / width, (y + 0.5) / height);
        // Angle from -Z, and the direction of (x, y) in the image plane.
        const double planar = std::hypot(d.x(), d.y());
        const double angle = std::atan2(planar, -d.z());  // [0, pi]
        const double r = angle / kPi;                     // [0, 1] of the half-width
        // On the Z axis the image direction is undefined; r is 0 (centre) or 1 (the rim,
        // which is all +Z), so any direction does.
        const double sx = planar > 0.0 ? r * d.x() / planar : r;
        const double sy = planar > 0.0 ? r * d.y() / planar : 0.0;
        // Image right is +X, image up is +Y, row 0 is the top; pixel i covers [i, i + 1).
        const double px = 0.5 * (sx + 1.0) * n;
        const double py = 0.5 * (1.0 - sy) * n;
        out[std::size_t(y) * std::size_t(width) + std::size_t(x)] = bilinear(angular, n, px, py);
      }
    }
  });
  return out;
}

}  // namespace

const char* layout_name(Layout layout) {
  switch (layout) {
    case Layout::kAuto:
      return "auto";
    case Layout::kLatLong:
      return "lat-long";
    case Layout::kAngular:
      return "angular";
  }
  return "unknown";
}

Probe load_probe(const std::filesystem::path& path, const LoadOptions& options,
                 LoadReport* report) {
  // Checked here because OpenImageIO's messages for these cases are misleading (a directory
  // gets "could not find a format reader").
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (status.type() == std::filesystem::file_type::not_found) fail(path, "no such file");
  if (ec) fail(path, "cannot be accessed: " + ec.message());
  if (std::filesystem::is_directory(status)) fail(path, "is a directory, not an image file");

  const std::uintmax_t file_size = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "cannot read its size: " + ec.message());
  if (const std::string problem = check_exr_header(path, file_size); !problem.empty()) {
    fail(path, problem);
  }

  std::unique_ptr<OIIO::ImageInput> in;
  try {
    in = OIIO::ImageInput::open(path.string());
  } catch (const std::bad_alloc&) {
    fail(path, "its header asks for more memory than there is; the file is damaged, re-export it");
  }
  if (!in) fail(path, "cannot be read as an image: " + OIIO::geterror());
  const OIIO::ImageSpec spec = in->spec();
  const int w = spec.width, h = spec.height, channels = spec.nchannels;
  const std::string size = std::to_string(w) + "x" + std::to_string(h);

  if (w <= 0 || h <= 0) fail(path, "empty image (" + size + ")");
  if (spec.depth > 1 || spec.deep) fail(path, "volume and deep images are not environment maps");
  // An EXR may store only part of its display window; the mapping needs the whole sphere.
  if (spec.full_width > 0 && spec.full_height > 0 &&
      (spec.x != spec.full_x || spec.y != spec.full_y || w != spec.full_width ||
       h != spec.full_height)) {
    fail(path, "its pixels (" + size + " at " + std::to_string(spec.x) + ", " +
                   std::to_string(spec.y) + ") do not cover its display window (" +
                   std::to_string(spec.full_width) + "x" + std::to_string(spec.full_height) +
                   "); re-export it with the data window equal to the display window");
  }
  if (channels == 2 || channels < 1) {
    fail(path, std::to_string(channels) +
                   " channels; need 3 or more (RGB, extra channels such as alpha are "
                   "ignored) or 1 (grey)");
  }

  Layout layout = options.layout;
  const bool latlong_shape = w == 2 * h, square = w == h;
  if (layout == Layout::kAuto) {
    if (latlong_shape) {
      layout = Layout::kLatLong;
    } else if (square) {
      layout = Layout::kAngular;
    } else {
      fail(path, size +
                     " is neither a 2:1 lat-long map nor a square angular map; crop or "
                     "resample it to one of those");
    }
  } else if (layout == Layout::kLatLong && !latlong_shape) {
    fail(path, size + " is not 2:1, but the layout was forced to lat-long");
  } else if (layout == Layout::kAngular && !square) {
    fail(path, size + " is not square, but the layout was forced to angular");
  }

  // Checked before anything is sized from the header.
  const double needed = double(w) * double(h) * kBytesPerTexel;
  if (needed > kAlwaysAllowedBytes && needed > double(file_size) * kMaxExpansion) {
    fail(path, "its header claims " + size + " texels, which would take " + gigabytes(needed) +
                   " to load, but a " + std::to_string(file_size) +
                   "-byte file cannot hold that many; the header is damaged, re-export the map");
  }
  if (const double available = available_memory(); available > 0 && needed > available) {
    fail(path, size + " texels need " + gigabytes(needed) + " to load but only " +
                   gigabytes(available) + " of memory is free; free memory or downsample the map");
  }

  // Read the first three channels (or the only one) as float.
  const int used = channels == 1 ? 1 : 3;
  const std::size_t texels = std::size_t(w) * std::size_t(h);
  std::vector<float> raw;
  try {
    raw.resize(texels * std::size_t(used));
    if (!in->read_image(0, 0, 0, used, OIIO::TypeDesc::FLOAT, raw.data())) {
      fail(path,
           "cannot read the pixels: " + in->geterror() + "; the file is damaged, re-export it");
    }
  } catch (const std::bad_alloc&) {
    fail(path, size + " texels are too large to load into memory; downsample the map");
  } catch (const std::length_error&) {
    fail(path, size + " texels are too large to load into memory; downsample the map");
  }
  const std::string format = in->format_name();
  in->close();

  float gamma = 1.0f;
  const Encoding encoding = encoding_of(spec, &gamma);

  std::vector<Rgb> rgb(texels);
  std::size_t bad = 0, first_bad = 0, negative = 0;
  for (std::size_t i = 0; i < texels; ++i) {
    Rgb t = used == 1 ? Rgb::Constant(raw[i]) : Rgb(raw[3 * i], raw[3 * i + 1], raw[3 * i + 2]);
    if (!t.allFinite()) {
      if (bad++ == 0) first_bad = i;
      continue;
    }
    if ((t.array() < 0.0f).any()) {
      ++negative;
      t = t.cwiseMax(0.0f);
    }
    if (encoding == Encoding::kSrgb) {
      for (int c = 0; c < 3; ++c) t[c] = srgb_to_linear(t[c]);
    } else if (encoding == Encoding::kGamma) {
      for (int c = 0; c < 3; ++c) t[c] = std::pow(t[c], gamma);
    }
    rgb[i] = t;
  }
  if (bad > 0) {
    std::ostringstream msg;
    msg << bad << " texel" << (bad == 1 ? " is" : "s are") << " NaN or Inf (the first at pixel ("
        << first_bad % std::size_t(w) << ", " << first_bad / std::size_t(w)
        << ")); the map is corrupt, re-export it";
    fail(path, msg.str());
  }

  int out_w = w, out_h = h;
  if (layout == Layout::kAngular) {
    rgb = angular_to_latlong(rgb, w);
    out_w = 2 * w;
    out_h = w;
  }

  if (report) {
    report->path = path.string();
    report->format = format;
    report->file_width = w;
    report->file_height = h;
    report->file_channels = channels;
    report->layout = layout;
    report->negative_texels_clamped = negative;
  }
  return Probe(out_w, out_h, std::move(rgb), path.stem().string());
}

}  // namespace probes
