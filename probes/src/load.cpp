// probes/load.cpp: the one seam to OpenImageIO for environment maps. Reads any format
// OpenImageIO reads, checks texels, and resamples angular ("light probe") maps to lat-long.
//
// Angular maps: P. Debevec, "Rendering synthetic objects into real scenes", SIGGRAPH 1998,
// and his Light Probe Image Gallery; the orientation used here is the one in probes/load.h.
#include "probes/load.h"

#include <OpenImageIO/imageio.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <new>
#include <numbers>
#include <sstream>
#include <system_error>
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

  auto in = OIIO::ImageInput::open(path.string());
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

  // Read the first three channels (or the only one) as float.
  const int used = channels == 1 ? 1 : 3;
  const std::size_t texels = std::size_t(w) * std::size_t(h);
  std::vector<float> raw;
  try {
    raw.resize(texels * std::size_t(used));
  } catch (const std::bad_alloc&) {
    fail(path, size + " is too large to load");
  }
  if (!in->read_image(0, 0, 0, used, OIIO::TypeDesc::FLOAT, raw.data())) {
    fail(path, "cannot read the pixels: " + in->geterror());
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
