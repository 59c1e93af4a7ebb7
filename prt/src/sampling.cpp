// Spherical Fibonacci point sets: Marques et al., "Spherical Fibonacci Point Sets for
// Illumination Integrals", CGF 2013. PCG32: O'Neill, "PCG: A Family of Simple Fast
// Space-Efficient Statistically Good Algorithms for Random Number Generation", 2014.
#include "prt/sampling.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace prt {

Pcg32::Pcg32(std::uint64_t seed, std::uint64_t stream)
    : state_(0), increment_((stream << 1u) | 1u) {
  next_u32();
  state_ += seed;
  next_u32();
}

std::uint32_t Pcg32::next_u32() {
  const std::uint64_t old = state_;
  state_ = old * 6364136223846793005ULL + increment_;
  const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
  const auto rot = static_cast<std::uint32_t>(old >> 59u);
  return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
}

double Pcg32::next_double() {
  const std::uint64_t hi = next_u32();
  const std::uint64_t lo = next_u32();
  return static_cast<double>(((hi << 32) | lo) >> 11) * 0x1.0p-53;
}

Eigen::Vector2d sobol02(std::uint32_t i, std::uint32_t shift_x, std::uint32_t shift_y) {
  std::uint32_t x = i;  // bit reversal: bit k of i becomes the k-th binary digit
  x = (x << 16) | (x >> 16);
  x = ((x & 0x00FF00FFu) << 8) | ((x >> 8) & 0x00FF00FFu);
  x = ((x & 0x0F0F0F0Fu) << 4) | ((x >> 4) & 0x0F0F0F0Fu);
  x = ((x & 0x33333333u) << 2) | ((x >> 2) & 0x33333333u);
  x = ((x & 0x55555555u) << 1) | ((x >> 1) & 0x55555555u);
  // The Pascal matrix mod 2: column k (bit k of i) holds binomial(k, r) in digit r.
  std::uint32_t y = 0;
  for (std::uint32_t column = 1u << 31; i != 0; i >>= 1, column ^= column >> 1)
    if (i & 1u) y ^= column;
  constexpr double kUnit = 0x1.0p-32;
  return {double(x ^ shift_x) * kUnit, double(y ^ shift_y) * kUnit};
}

namespace {

void check_count(int count) {
  if (count < 1) {
    throw std::invalid_argument("direction count must be >= 1, got " + std::to_string(count));
  }
}

// Golden-ratio lattice with z running over `count` equal strata of [z_min, 1].
Eigen::Matrix3Xd fibonacci(int count, double z_min, double phase) {
  const double golden = (std::sqrt(5.0) - 1.0) / 2.0;  // 1 / phi
  Eigen::Matrix3Xd out(3, count);
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - (1.0 - z_min) * (i + 0.5) / count;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    double frac = i * golden + phase;
    frac -= std::floor(frac);
    const double phi = 2.0 * std::numbers::pi * frac;
    out.col(i) << r * std::cos(phi), r * std::sin(phi), z;
  }
  return out;
}

}  // namespace

DirectionSet sphere_directions(int count, std::uint64_t seed) {
  check_count(count);
  Pcg32 rng(seed);
  const double phase = rng.next_double();
  DirectionSet set;
  set.directions = random_rotation(rng) * fibonacci(count, -1.0, phase);
  set.weight = 4.0 * std::numbers::pi / count;
  return set;
}

DirectionSet hemisphere_directions(int count, std::uint64_t seed) {
  check_count(count);
  Pcg32 rng(seed);
  // Only a phase in phi: a general rotation would leave the hemisphere.
  DirectionSet set;
  set.directions = fibonacci(count, 0.0, rng.next_double());
  set.weight = 2.0 * std::numbers::pi / count;
  return set;
}

Eigen::Vector3d sample_uniform_sphere(double u1, double u2) {
  const double z = 1.0 - 2.0 * u1;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = 2.0 * std::numbers::pi * u2;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

Eigen::Vector3d sample_cosine_hemisphere(double u1, double u2) {
  const double r = std::sqrt(u1);
  const double phi = 2.0 * std::numbers::pi * u2;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u1))};
}

double cosine_hemisphere_pdf(const Eigen::Vector3d& direction) {
  return direction.z() > 0.0 ? direction.z() / std::numbers::pi : 0.0;
}

Eigen::Matrix3d random_rotation(Pcg32& rng) {
  const double u1 = rng.next_double(), u2 = rng.next_double(), u3 = rng.next_double();
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  const double t2 = 2.0 * std::numbers::pi * u2, t3 = 2.0 * std::numbers::pi * u3;
  const Eigen::Quaterniond q(b * std::cos(t3), a * std::sin(t2), a * std::cos(t2),
                             b * std::sin(t3));
  return q.normalized().toRotationMatrix();
}

}  // namespace prt
