// Direction sets: unit length, coverage, quadrature accuracy, determinism.
#include "prt/sampling.h"

#include "prt/sh.h"

#include <gtest/gtest.h>
#include <Eigen/LU>

#include <cmath>
#include <numbers>
#include <vector>

namespace {

TEST(Sampling, Pcg32IsDeterministicAndUniform) {
  prt::Pcg32 a(123), b(123), c(124);
  EXPECT_EQ(a.next_u32(), b.next_u32());
  EXPECT_NE(prt::Pcg32(123).next_u32(), c.next_u32());
  double mean = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const double u = a.next_double();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    mean += u / n;
  }
  EXPECT_NEAR(mean, 0.5, 5 * std::sqrt(1.0 / 12 / n));  // 5 sigma
}

TEST(Sampling, SphereSetIntegratesSmoothFunctions) {
  // The lattice integrates low-order SH to O(1/count): integral y_0 = sqrt(4 pi), others 0.
  const prt::DirectionSet set = prt::sphere_directions(1024, 5);
  ASSERT_EQ(set.size(), 1024);
  EXPECT_NEAR(set.weight * set.size(), 4 * std::numbers::pi, 1e-12);
  Eigen::VectorXd integral = Eigen::VectorXd::Zero(36);
  double y[36];
  for (int k = 0; k < set.size(); ++k) {
    ASSERT_NEAR(set.directions.col(k).norm(), 1.0, 1e-12);
    prt::sh_eval(6, Eigen::Vector3d(set.directions.col(k)), y);
    integral += set.weight * Eigen::Map<Eigen::VectorXd>(y, 36);
  }
  EXPECT_NEAR(integral[0], std::sqrt(4 * std::numbers::pi), 1e-12);
  // A random set of 1024 would give errors ~ sqrt(4 pi / 1024) ~ 0.1; the lattice ~1e-2.
  EXPECT_LT(integral.tail(35).cwiseAbs().maxCoeff(), 2e-2);
}

TEST(Sampling, HemisphereSetStaysAbove) {
  const prt::DirectionSet set = prt::hemisphere_directions(500, 2);
  for (int k = 0; k < set.size(); ++k) EXPECT_GT(set.directions(2, k), 0.0);
  // Integral of cos over the hemisphere is pi.
  EXPECT_NEAR(set.directions.row(2).sum() * set.weight, std::numbers::pi, 1e-3);
}

TEST(Sampling, SeedsAreDeterministicAndDistinct) {
  const auto a = prt::sphere_directions(64, 1), b = prt::sphere_directions(64, 1);
  const auto c = prt::sphere_directions(64, 2);
  EXPECT_EQ(a.directions, b.directions);
  EXPECT_GT((a.directions - c.directions).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_THROW(prt::sphere_directions(0, 1), std::invalid_argument);
}

TEST(Sampling, CosineHemisphereMatchesItsDistribution) {
  // Under p = cos(theta) / pi: E[cos theta] = 2/3 and P(theta < t) = sin^2 t.
  prt::Pcg32 rng(8);
  const int n = 40000;
  double mean_z = 0, below_45 = 0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d d = prt::sample_cosine_hemisphere(rng.next_double(), rng.next_double());
    ASSERT_NEAR(d.norm(), 1.0, 1e-12);
    ASSERT_NEAR(prt::cosine_hemisphere_pdf(d), d.z() / std::numbers::pi, 1e-15);
    mean_z += d.z() / n;
    below_45 += (d.z() > std::cos(std::numbers::pi / 4)) ? 1.0 / n : 0.0;
  }
  // Standard deviations: z has variance 1/2 - 4/9 = 1/18; the indicator 1/4. Allow 5 sigma.
  EXPECT_NEAR(mean_z, 2.0 / 3.0, 5 * std::sqrt(1.0 / 18 / n));
  EXPECT_NEAR(below_45, 0.5, 5 * std::sqrt(0.25 / n));
}

TEST(Sampling, RandomRotationIsARotation) {
  prt::Pcg32 rng(4);
  for (int i = 0; i < 10; ++i) {
    const Eigen::Matrix3d r = prt::random_rotation(rng);
    EXPECT_LT((r * r.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  }
}

TEST(Sampling, Sobol02StartsAsSobolsSequence) {
  // Sobol's first two dimensions in index order (not Gray-code order): the radical inverse
  // 0, 1/2, 1/4, 3/4, 1/8, 5/8 and the Pascal matrix's 0, 1/2, 3/4, 1/4, 5/8, 1/8.
  const double x[] = {0, 0.5, 0.25, 0.75, 0.125, 0.625};
  const double y[] = {0, 0.5, 0.75, 0.25, 0.625, 0.125};
  for (std::uint32_t i = 0; i < 6; ++i) {
    EXPECT_EQ(prt::sobol02(i, 0, 0).x(), x[i]) << i;
    EXPECT_EQ(prt::sobol02(i, 0, 0).y(), y[i]) << i;
  }
}

TEST(Sampling, Sobol02BlocksAreNetsUnderAnyShift) {
  // A (0, m, 2)-net: every aligned block of 2^m points, shifted or not, puts exactly one point
  // in each 2^-a x 2^-(m-a) box, for every a; the defining property of a (0, 2)-sequence.
  prt::Pcg32 rng(9);
  for (int m = 0; m <= 8; ++m) {
    const std::uint32_t n = 1u << m;
    for (const std::uint32_t block : {0u, 1u, 7u, 1000003u}) {
      const std::uint32_t shift_x = block == 0 ? 0 : rng.next_u32();
      const std::uint32_t shift_y = block == 0 ? 0 : rng.next_u32();
      for (int a = 0; a <= m; ++a) {
        std::vector<int> count(n, 0);
        for (std::uint32_t i = 0; i < n; ++i) {
          const Eigen::Vector2d p = prt::sobol02(block * n + i, shift_x, shift_y);
          ASSERT_TRUE(p.x() >= 0 && p.x() < 1 && p.y() >= 0 && p.y() < 1);
          const auto bx = std::uint32_t(p.x() * double(1u << a));
          const auto by = std::uint32_t(p.y() * double(1u << (m - a)));
          ++count[(bx << (m - a)) | by];
        }
        for (std::uint32_t box = 0; box < n; ++box)
          ASSERT_EQ(count[box], 1) << "m " << m << " a " << a << " block " << block;
      }
    }
  }
}

}  // namespace
