// probes/load.cpp: the one seam to OpenImageIO for environment maps. Reads any format
// OpenImageIO reads, checks texels, and resamples angular ("light probe") maps to lat-long.
//
// Angular maps: P. Debevec, "Rendering synthetic objects into real scenes", SIGGRAPH 1998,
// and his Light Probe Image Gallery; the orientation used here is the one in probes/load.h.
#include "probes/load.h"

#include "common/image_codec.h"
#include "exr_guard.h"
#include "rgbe_file.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <unistd.h>

#include <algorithm>
#include <array>
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
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <utility>
#include <vector>

namespace probes {

namespace {

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

// Bytes this loader allocates per texel: the float read buffer (up to three channels) and
// the Rgb array.
constexpr double kBytesPerTexel = 3 * sizeof(float) + sizeof(Rgb);
using detail::kAlwaysAllowedBytes;
using detail::kMaxExpansion;

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

Encoding encoding_of(const common::ImageHeader& header, float* gamma) {
  const std::string space = lower(header.color_space);
  *gamma = header.gamma;
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
  if (space.empty() && !header.floating_point) return Encoding::kSrgb;
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
        const double r = angle / std::numbers::pi;        // [0, 1] of the half-width
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

// --- One image file -------------------------------------------------------------------------

struct Image {
  std::vector<Rgb> rgb;
  int width = 0, height = 0, channels = 0;
  std::string format;
  std::size_t negative = 0;
};

// Checks that OpenImageIO's messages would get wrong (a directory gets "could not find a
// format reader"), then the OpenEXR header guard; returns the file's size.
std::uintmax_t check_file(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (status.type() == std::filesystem::file_type::not_found) fail(path, "no such file");
  if (ec) fail(path, "cannot be accessed: " + ec.message());
  if (std::filesystem::is_directory(status)) fail(path, "is a directory, not an image file");
  const std::uintmax_t file_size = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "cannot read its size: " + ec.message());
  if (const std::string problem = detail::check_exr_header(path, file_size); !problem.empty()) {
    fail(path, problem);
  }
  return file_size;
}

// The spec checks made before anything is sized from the header.
void check_spec(const std::filesystem::path& path, const common::ImageHeader& spec,
                std::uintmax_t file_size) {
  const int w = spec.width, h = spec.height, channels = spec.channels;
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
}

// Float texels to linear RGB: grey to RGB, NaN/Inf refused, negatives clamped, decoded.
void decode(const std::filesystem::path& path, const std::vector<float>& raw, int used,
            const common::ImageHeader& spec, Image& image) {
  float gamma = 1.0f;
  const Encoding encoding = encoding_of(spec, &gamma);
  const std::size_t texels = std::size_t(image.width) * std::size_t(image.height);
  image.rgb.resize(texels);
  std::size_t bad = 0, first_bad = 0;
  for (std::size_t i = 0; i < texels; ++i) {
    Rgb t = used == 1 ? Rgb::Constant(raw[i]) : Rgb(raw[3 * i], raw[3 * i + 1], raw[3 * i + 2]);
    if (!t.allFinite()) {
      if (bad++ == 0) first_bad = i;
      continue;
    }
    if ((t.array() < 0.0f).any()) {
      ++image.negative;
      t = t.cwiseMax(0.0f);
    }
    if (encoding == Encoding::kSrgb) {
      for (int c = 0; c < 3; ++c) t[c] = srgb_to_linear(t[c]);
    } else if (encoding == Encoding::kGamma) {
      for (int c = 0; c < 3; ++c) t[c] = std::pow(t[c], gamma);
    }
    image.rgb[i] = t;
  }
  if (bad > 0) {
    std::ostringstream msg;
    msg << bad << " texel" << (bad == 1 ? " is" : "s are") << " NaN or Inf (the first at pixel ("
        << first_bad % std::size_t(image.width) << ", " << first_bad / std::size_t(image.width)
        << ")); the map is corrupt, re-export it";
    fail(path, msg.str());
  }
}

Image read_image(const std::filesystem::path& path) {
  const std::uintmax_t file_size = check_file(path);
  std::unique_ptr<common::ImageFile> in;
  std::string error;
  if (detail::is_rgbe(path)) {
    in = detail::open_rgbe(path, &error);
    if (!in) fail(path, error);
  } else {
    try {
      in = common::image_codec().open(path.string(), &error);
    } catch (const std::bad_alloc&) {
      fail(path,
           "its header asks for more memory than there is; the file is damaged, re-export it");
    }
    if (!in) fail(path, "cannot be read as an image: " + error);
  }
  const common::ImageHeader& spec = in->header();
  check_spec(path, spec, file_size);
  Image image;
  image.width = spec.width;
  image.height = spec.height;
  image.channels = spec.channels;
  // Read the first three channels (or the only one) as float.
  const int used = image.channels == 1 ? 1 : 3;
  const std::string too_large = std::to_string(image.width) + "x" + std::to_string(image.height) +
                                " texels are too large to load into memory; downsample the map";
  std::vector<float> raw;
  try {
    raw.resize(std::size_t(image.width) * std::size_t(image.height) * std::size_t(used));
    if (!in->read(used, raw.data(), &error)) {
      fail(path, "cannot read the pixels: " + error + "; the file is damaged, re-export it");
    }
  } catch (const std::bad_alloc&) {
    fail(path, too_large);
  } catch (const std::length_error&) {
    fail(path, too_large);
  }
  image.format = spec.format;
  decode(path, raw, used, spec, image);
  return image;
}

// --- Six face files ------------------------------------------------------------------------

constexpr std::string_view kFacePlaceholder = "{face}";

bool names_face_set(const std::filesystem::path& path) {
  std::error_code ec;
  return path.string().find(kFacePlaceholder) != std::string::npos ||
         std::filesystem::is_directory(path, ec);
}

// The file of `face` in a set: the pattern with {face} replaced, or the one file in the
// folder whose name without extension is the face's name.
std::filesystem::path face_file(const std::filesystem::path& set, int face) {
  const std::string name = cube_face_name(face);
  std::string pattern = set.string();
  if (const std::size_t at = pattern.find(kFacePlaceholder); at != std::string::npos) {
    return pattern.replace(at, kFacePlaceholder.size(), name);
  }
  std::vector<std::filesystem::path> found;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(set, ec)) {
    if (entry.path().stem() == name) found.push_back(entry.path());
  }
  if (found.size() != 1) {
    fail(set, found.empty() ? "is a folder without a " + name +
                                  ".* face file; a six-face cube map needs px, nx, py, ny, "
                                  "pz and nz (for example px.exr)"
                            : "holds several " + name + ".* files; keep one per face");
  }
  return found[0];
}

CubeMap read_face_set(const std::filesystem::path& set, LoadReport* report) {
  std::array<std::vector<Rgb>, kCubeFaces> faces;
  int size = 0;
  for (int f = 0; f < kCubeFaces; ++f) {
    const std::filesystem::path file = face_file(set, f);
    Image image = read_image(file);
    if (image.width != image.height) {
      fail(file, std::to_string(image.width) + "x" + std::to_string(image.height) +
                     " is not square; every cube face must be N x N");
    }
    if (f > 0 && image.width != size) {
      fail(file, "is " + std::to_string(image.width) + " texels wide but face px is " +
                     std::to_string(size) + "; every cube face must be the same size");
    }
    size = image.width;
    faces[std::size_t(f)] = std::move(image.rgb);
    if (report) {
      report->format = image.format;
      report->file_channels = image.channels;
      report->negative_texels_clamped += image.negative;
    }
  }
  if (report) report->file_width = report->file_height = size;
  return CubeMap(size, std::move(faces));
}

// The layout of one image file: forced, or by aspect ratio.
Layout choose_layout(const std::filesystem::path& path, Layout forced, int w, int h) {
  const std::string size = std::to_string(w) + "x" + std::to_string(h);
  const bool latlong = w == 2 * h, square = w == h;
  const bool cross = (3 * w == 4 * h && w % 4 == 0) || (4 * w == 3 * h && w % 3 == 0);
  switch (forced) {
    case Layout::kLatLong:
      if (!latlong) fail(path, size + " is not 2:1, but the layout was forced to lat-long");
      return forced;
    case Layout::kAngular:
      if (!square) fail(path, size + " is not square, but the layout was forced to angular");
      return forced;
    case Layout::kCross:
      if (!cross) {
        fail(path, size +
                       " is neither a 4:3 horizontal nor a 3:4 vertical cross of square "
                       "faces, but the layout was forced to cross");
      }
      return forced;
    case Layout::kFaces:
      fail(path,
           "the layout was forced to faces, which needs a folder holding px, nx, py, ny, "
           "pz and nz, or a file name with {face} in it");
    case Layout::kAuto:
      break;
  }
  if (latlong) return Layout::kLatLong;
  if (square) return Layout::kAngular;
  if (cross) return Layout::kCross;
  fail(path, size +
                 " is neither a 2:1 lat-long map, a square angular map nor a 4:3 or 3:4 cube "
                 "cross; crop or resample it to one of those");
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
    case Layout::kCross:
      return "cube cross";
    case Layout::kFaces:
      return "cube faces";
  }
  return "unknown";
}

Probe load_probe(const std::filesystem::path& path, const LoadOptions& options,
                 LoadReport* report) {
  LoadReport local;
  LoadReport& r = report ? *report : local;
  r = LoadReport{};
  r.path = path.string();
  const std::string name = path.stem().string();
  if (names_face_set(path) && options.layout != Layout::kLatLong &&
      options.layout != Layout::kAngular && options.layout != Layout::kCross) {
    r.layout = Layout::kFaces;
    r.cube = std::make_shared<const CubeMap>(read_face_set(path, &r));
    Probe probe = cube_to_latlong(*r.cube, path.filename().string());
    probe.set_source_cube(r.cube);
    return probe;
  }
  Image image = read_image(path);
  r.format = image.format;
  r.file_width = image.width;
  r.file_height = image.height;
  r.file_channels = image.channels;
  r.negative_texels_clamped = image.negative;
  r.layout = choose_layout(path, options.layout, image.width, image.height);
  switch (r.layout) {
    case Layout::kAngular:
      return Probe(2 * image.width, image.width, angular_to_latlong(image.rgb, image.width), name);
    case Layout::kCross: {
      r.cross = image.width > image.height ? CrossKind::kHorizontal : CrossKind::kVertical;
      r.cube = std::make_shared<const CubeMap>(
          cube_from_cross(image.rgb, image.width, image.height, r.cross));
      Probe probe = cube_to_latlong(*r.cube, name);
      probe.set_source_cube(r.cube);
      return probe;
    }
    default:
      return Probe(image.width, image.height, std::move(image.rgb), name);
  }
}

}  // namespace probes
