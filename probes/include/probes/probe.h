// probes/probe.h: a distant environment ("light probe") stored as a lat-long radiance map.
//
// Direction <-> pixel convention (the only one in the engine; render/ and prt/ use these
// functions rather than repeating the formulas):
//  - World is right-handed, +Y up. Radiance is linear RGB in the file's units.
//  - Pixel (x, y) covers u in [x/W, (x+1)/W), v in [y/H, (y+1)/H); its centre is at
//    ((x + 0.5)/W, (y + 0.5)/H). Row 0 is the top of the image.
//  - theta = pi * v is the angle from +Y (v = 0 is straight up, v = 1 straight down);
//    phi = 2 pi u, and
//        direction(u, v) = (-sin(theta) sin(phi), cos(theta), sin(theta) cos(phi)).
//    So the image centre (u = 0.5) looks toward -Z (what a default camera looking down -Z
//    sees behind the object), u = 0.75 toward +X (to its right), u = 0.25 toward -X, and
//    u = 0 (the left/right seam) toward +Z. Seen from inside, the map is not mirrored.
//    This is Blender's equirectangular world mapping turned 90 degrees about the up axis.
//  - Angular ("light probe") maps are resampled to lat-long on load; see probes/load.h.
#pragma once

#include <Eigen/Core>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace probes {

using Vec3 = Eigen::Vector3f;
using Rgb = Eigen::Vector3f;

// Map from the unit square to directions and back (see the convention above).
Eigen::Vector3d latlong_direction(double u, double v);
Eigen::Vector2d latlong_uv(const Eigen::Vector3d& direction);  // direction need not be unit

class CubeMap;

// The largest |radiance| a texel may hold: beyond it single-precision lighting overflows.
inline constexpr float kMaxRadiance = 1e20f;

class Probe {
 public:
  Probe() = default;
  // `rgb` holds width * height texels, row-major from the top row. Requires width == 2 *
  // height and finite texels. Negative values are allowed so that signed test functions
  // (a single SH basis function) can be represented; the file loader never produces them.
  Probe(int width, int height, std::vector<Rgb> rgb, std::string name = {});

  int width() const { return width_; }
  int height() const { return height_; }
  const std::string& name() const { return name_; }
  const std::vector<Rgb>& texels() const { return rgb_; }
  const Rgb& texel(int x, int y) const { return rgb_[std::size_t(y) * width_ + x]; }

  // Centre direction of pixel (x, y), unit length.
  Eigen::Vector3d pixel_direction(int x, int y) const;
  // Solid angle of a pixel in row y: (2 pi / W) (cos theta_top - cos theta_bottom); exact,
  // and the sum over the image is 4 pi.
  double pixel_solid_angle(int y) const;
  // Bilinear radiance lookup between pixel centres; wraps in u, clamps in v.
  Rgb lookup(const Eigen::Vector3d& direction) const;
  // The same at lat-long coordinates uv = latlong_uv(direction), for a caller that has them.
  Rgb lookup_uv(const Eigen::Vector2d& uv) const;
  // Nearest-pixel lookup, for tests and previews.
  Rgb lookup_nearest(const Eigen::Vector3d& direction) const;

  // Statistics printed by `prtr probe`.
  Rgb max_texel() const;
  // Integral of radiance over the sphere divided by 4 pi (solid-angle weighted mean).
  Rgb mean_radiance() const;

  // A probe read from a cube map is the cube's lat-long resampling (what lookups and the
  // background use); the cube itself rides along so that SH projection can integrate its own
  // texels exactly instead of the resampling (prt::project).
  const CubeMap* source_cube() const { return cube_.get(); }
  void set_source_cube(std::shared_ptr<const CubeMap> cube) { cube_ = std::move(cube); }

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<Rgb> rgb_;
  std::string name_;
  std::shared_ptr<const CubeMap> cube_;
};

class ProbeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace probes
