// probes/procedural.cpp: environments built in code (constant, any function of direction, a
// sun disc), for tests and examples. All of them sample the pixel centres of
// probes/probe.h's convention.
#include "probes/procedural.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Geometry>

#include <cmath>
#include <sstream>
#include <string>
#include <utility>

namespace probes {

namespace {

// Checked before allocating: a negative size would otherwise become a huge allocation.
void check_size(const char* what, int width, int height) {
  if (height < 1 || width != 2 * height) {
    std::ostringstream msg;
    msg << what << ": size " << width << "x" << height
        << " is not a lat-long map (need height >= 1 and width == 2 * height)";
    throw ProbeError(msg.str());
  }
}

}  // namespace

Probe make_constant(int width, int height, const Rgb& radiance) {
  check_size("make_constant", width, height);
  std::vector<Rgb> rgb(std::size_t(width) * std::size_t(height), radiance);
  return Probe(width, height, std::move(rgb), "constant");
}

Probe make_from_function(int width, int height,
                         const std::function<Rgb(const Eigen::Vector3d&)>& radiance) {
  check_size("make_from_function", width, height);
  std::vector<Rgb> rgb(std::size_t(width) * std::size_t(height));
  // Each texel depends only on its own pixel, so the result does not depend on scheduling.
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      for (int x = 0; x < width; ++x) {
        const Eigen::Vector3d d = latlong_direction((x + 0.5) / width, (y + 0.5) / height);
        rgb[std::size_t(y) * std::size_t(width) + std::size_t(x)] = radiance(d);
      }
    }
  });
  return Probe(width, height, std::move(rgb), "function");
}

Probe make_sun(int width, int height, const Eigen::Vector3d& direction, double radius_radians,
               const Rgb& radiance) {
  check_size("make_sun", width, height);
  const double length = direction.norm();
  if (!(length > 0.0) || !std::isfinite(length)) {
    std::ostringstream msg;
    msg << "make_sun: the sun direction (" << direction.x() << ", " << direction.y() << ", "
        << direction.z() << ") is not a finite non-zero vector";
    throw ProbeError(msg.str());
  }
  if (!(radius_radians >= 0.0) || !std::isfinite(radius_radians)) {
    std::ostringstream msg;
    msg << "make_sun: the angular radius " << radius_radians << " is not finite and >= 0";
    throw ProbeError(msg.str());
  }
  const Eigen::Vector3d centre = direction / length;
  std::vector<Rgb> rgb(std::size_t(width) * std::size_t(height), Rgb::Zero());
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Eigen::Vector3d d = latlong_direction((x + 0.5) / width, (y + 0.5) / height);
      // The angle by atan2(|a x b|, a . b) stays accurate for the small radii of real suns,
      // where acos(a . b) loses half its digits.
      const double angle = std::atan2(d.cross(centre).norm(), d.dot(centre));
      if (angle <= radius_radians) rgb[std::size_t(y) * std::size_t(width) + x] = radiance;
    }
  }
  return Probe(width, height, std::move(rgb), "sun");
}

}  // namespace probes
