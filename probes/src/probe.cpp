// probes/probe.cpp: the lat-long direction <-> pixel convention (documented once, in
// probes/probe.h) and radiance lookups and statistics on a probe.
#include "probes/probe.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <utility>

namespace probes {

namespace {

constexpr double kPi = std::numbers::pi;

// "probe 'name'" or "probe" when unnamed, for error messages.
std::string describe(const std::string& name) {
  return name.empty() ? std::string("probe") : "probe '" + name + "'";
}

// A lookup into an empty probe or along a NaN/Inf direction is a caller's bug; without this
// check it would index out of bounds.
void check_lookup(const std::string& name, bool empty, const Eigen::Vector3d& direction) {
  if (empty) throw ProbeError(describe(name) + ": lookup in an empty probe");
  if (!direction.allFinite()) {
    std::ostringstream msg;
    msg << describe(name) << ": lookup with a non-finite direction (" << direction.x() << ", "
        << direction.y() << ", " << direction.z() << ")";
    throw ProbeError(msg.str());
  }
}

int wrap(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}

}  // namespace

// --- Convention ------------------------------------------------------------------------------

Eigen::Vector3d latlong_direction(double u, double v) {
  const double theta = kPi * v;
  const double phi = 2.0 * kPi * u;
  const double s = std::sin(theta);
  return {-s * std::sin(phi), std::cos(theta), s * std::cos(phi)};
}

Eigen::Vector2d latlong_uv(const Eigen::Vector3d& direction) {
  const double x = direction.x(), y = direction.y(), z = direction.z();
  // atan2 of (sin, cos) rather than acos(y / |d|): accurate near the poles, and needs no
  // normalisation. At a pole (x = z = 0) atan2(0, 0) = 0 gives u = 0.
  const double theta = std::atan2(std::hypot(x, z), y);  // [0, pi]
  const double phi = std::atan2(-x, z);                  // (-pi, pi]
  double u = phi / (2.0 * kPi);
  if (u < 0.0) u += 1.0;
  if (u >= 1.0) u = 0.0;  // -tiny + 1 rounds to 1; that is the seam, u = 0
  u += 0.0;               // turns -0 into +0
  return {u, theta / kPi};
}

// --- Probe -----------------------------------------------------------------------------------

Probe::Probe(int width, int height, std::vector<Rgb> rgb, std::string name)
    : width_(width), height_(height), rgb_(std::move(rgb)), name_(std::move(name)) {
  if (height_ < 1 || width_ != 2 * height_) {
    std::ostringstream msg;
    msg << describe(name_) << ": size " << width_ << "x" << height_
        << " is not a lat-long map (need height >= 1 and width == 2 * height)";
    throw ProbeError(msg.str());
  }
  const std::size_t expected = std::size_t(width_) * std::size_t(height_);
  if (rgb_.size() != expected) {
    std::ostringstream msg;
    msg << describe(name_) << ": " << rgb_.size() << " texels given for a " << width_ << "x"
        << height_ << " map (expected " << expected << ")";
    throw ProbeError(msg.str());
  }
  // Past kMaxRadiance the SH projection (a sum of 4 pi worth of texels) and the shading
  // products overflow single precision into Inf and then NaN pixels.
  for (std::size_t i = 0; i < rgb_.size(); ++i) {
    if (!rgb_[i].allFinite() || rgb_[i].cwiseAbs().maxCoeff() > kMaxRadiance) {
      std::ostringstream msg;
      msg << describe(name_) << ": texel (" << i % std::size_t(width_) << ", "
          << i / std::size_t(width_) << ") is "
          << (rgb_[i].allFinite() ? "beyond the largest radiance prtr takes, 1e20," : "not finite")
          << " (" << rgb_[i].x() << ", " << rgb_[i].y() << ", " << rgb_[i].z()
          << "); rescale the probe";
      throw ProbeError(msg.str());
    }
  }
}

Eigen::Vector3d Probe::pixel_direction(int x, int y) const {
  return latlong_direction((x + 0.5) / width_, (y + 0.5) / height_);
}

double Probe::pixel_solid_angle(int y) const {
  // cos(a) - cos(b) = 2 sin((a + b) / 2) sin((b - a) / 2): no cancellation for thin rows
  // near the poles, where the two cosines are both close to +-1.
  const double dtheta = kPi / height_;
  const double theta_mid = (y + 0.5) * dtheta;
  return (2.0 * kPi / width_) * 2.0 * std::sin(theta_mid) * std::sin(0.5 * dtheta);
}

Rgb Probe::lookup(const Eigen::Vector3d& direction) const {
  check_lookup(name_, rgb_.empty(), direction);
  return lookup_uv(latlong_uv(direction));
}

Rgb Probe::lookup_uv(const Eigen::Vector2d& uv) const {
  if (rgb_.empty()) throw ProbeError(describe(name_) + ": lookup in an empty probe");
  if (!uv.allFinite()) {
    std::ostringstream msg;
    msg << describe(name_) << ": lookup at non-finite lat-long coordinates (" << uv.x() << ", "
        << uv.y() << ")";
    throw ProbeError(msg.str());
  }
  // Continuous pixel coordinates whose integers are pixel centres.
  const double fx = uv.x() * width_ - 0.5;
  const double fy = uv.y() * height_ - 0.5;
  const double x_floor = std::floor(fx), y_floor = std::floor(fy);
  const float tx = float(fx - x_floor), ty = float(fy - y_floor);
  const int x0 = wrap(int(x_floor), width_), x1 = wrap(int(x_floor) + 1, width_);
  const int y0 = std::clamp(int(y_floor), 0, height_ - 1);
  const int y1 = std::clamp(int(y_floor) + 1, 0, height_ - 1);
  const Rgb top = (1.0f - tx) * texel(x0, y0) + tx * texel(x1, y0);
  const Rgb bottom = (1.0f - tx) * texel(x0, y1) + tx * texel(x1, y1);
  return (1.0f - ty) * top + ty * bottom;
}

Rgb Probe::lookup_nearest(const Eigen::Vector3d& direction) const {
  check_lookup(name_, rgb_.empty(), direction);
  const Eigen::Vector2d uv = latlong_uv(direction);
  // u < 1 and v <= 1, but u * W can round up to W and v = 1 gives H: clamp both.
  const int x = std::clamp(int(uv.x() * width_), 0, width_ - 1);
  const int y = std::clamp(int(uv.y() * height_), 0, height_ - 1);
  return texel(x, y);
}

Rgb Probe::max_texel() const {
  if (rgb_.empty()) return Rgb::Zero();
  Rgb m = rgb_.front();
  for (const Rgb& t : rgb_) m = m.cwiseMax(t);
  return m;
}

Rgb Probe::mean_radiance() const {
  if (rgb_.empty()) return Rgb::Zero();
  Eigen::Vector3d integral = Eigen::Vector3d::Zero();
  for (int y = 0; y < height_; ++y) {
    Eigen::Vector3d row = Eigen::Vector3d::Zero();
    for (int x = 0; x < width_; ++x) row += texel(x, y).cast<double>();
    integral += pixel_solid_angle(y) * row;
  }
  return (integral / (4.0 * kPi)).cast<float>();
}

}  // namespace probes
