// prt/sampling.h: deterministic direction sets and a small seeded random generator.
//
// Direction sets are spherical Fibonacci lattices (equal-area strata in z, golden-ratio
// steps in phi), turned by a rotation drawn from the seed, so two seeds give different but
// equally good sets and one seed always gives the same bytes. Every direction carries the
// same quadrature weight: 4 pi / count on the sphere, 2 pi / count on the hemisphere.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <numbers>

namespace prt {

// PCG32 (O'Neill 2014): small state, good statistics, identical output on every platform.
class Pcg32 {
 public:
  explicit Pcg32(std::uint64_t seed, std::uint64_t stream = 0x2545F4914F6CDD1DULL);
  std::uint32_t next_u32();
  // Uniform in [0, 1) with 53 random bits (two draws).
  double next_double();

 private:
  std::uint64_t state_;
  std::uint64_t increment_;
};

struct DirectionSet {
  Eigen::Matrix3Xd directions;  // unit columns
  double weight = 0.0;          // quadrature weight per direction
  Eigen::Index size() const { return directions.cols(); }
};

// `count` directions over the whole sphere. Throws std::invalid_argument for count < 1.
DirectionSet sphere_directions(int count, std::uint64_t seed);
// `count` directions over the hemisphere z > 0.
DirectionSet hemisphere_directions(int count, std::uint64_t seed);

// Uniform sphere sampling from two uniforms, and its density (1 / 4 pi).
Eigen::Vector3d sample_uniform_sphere(double u1, double u2);
inline double uniform_sphere_pdf() {
  return 0.25 / std::numbers::pi;
}
// Cosine-weighted hemisphere about +Z, and its density cos(theta) / pi.
Eigen::Vector3d sample_cosine_hemisphere(double u1, double u2);
double cosine_hemisphere_pdf(const Eigen::Vector3d& direction);

// A rotation drawn uniformly from SO(3) (Shoemake's uniform quaternion).
Eigen::Matrix3d random_rotation(Pcg32& rng);

// Point i of the (0, 2)-sequence in base 2 (Sobol's first two dimensions: van der Corput's
// radical inverse and the Pascal matrix's), its coordinates' bits XORed with `shift` (a
// random digital shift; Kollig & Keller 2002). With a uniform shift every point is uniform
// over [0, 1)^2, and any 2^m points i = k 2^m .. (k + 1) 2^m - 1 still put one point in each
// 2^-a x 2^-(m-a) box of the square: a run of consecutive indices is spread over the whole
// square, not over a strip of it.
Eigen::Vector2d sobol02(std::uint32_t i, std::uint32_t shift_x, std::uint32_t shift_y);

}  // namespace prt
