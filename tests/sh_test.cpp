// SH basis: the fast recurrence against the textbook formula, orthonormality by quadrature,
// and the sign/axis conventions written in prt/sh.h.
#include "prt/sh.h"
#include "prt/sampling.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

namespace {

using test_support::gauss_legendre;

TEST(Sh, IndexAndBand) {
  EXPECT_EQ(prt::sh_count(6), 36);
  EXPECT_EQ(prt::sh_index(0, 0), 0);
  EXPECT_EQ(prt::sh_index(1, -1), 1);
  EXPECT_EQ(prt::sh_index(5, 5), 35);
  for (int l = 0; l < prt::kMaxOrder; ++l)
    for (int m = -l; m <= l; ++m) EXPECT_EQ(prt::sh_band(prt::sh_index(l, m)), l);
}

TEST(Sh, OrderIsChecked) {
  EXPECT_THROW(prt::check_order(0), std::invalid_argument);
  EXPECT_THROW(prt::check_order(11), std::invalid_argument);
  EXPECT_NO_THROW(prt::check_order(10));
}

TEST(Sh, LowBandsMatchClosedForms) {
  // y_0 = 1 / (2 sqrt(pi)); y_1 = sqrt(3 / (4 pi)) (y, z, x), no Condon-Shortley phase.
  const Eigen::Vector3d d = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  double y[4];
  prt::sh_eval(2, d, y);
  const double c1 = std::sqrt(3.0 / (4.0 * std::numbers::pi));
  EXPECT_NEAR(y[0], 0.5 / std::sqrt(std::numbers::pi), 1e-15);
  EXPECT_NEAR(y[1], c1 * d.y(), 1e-15);
  EXPECT_NEAR(y[2], c1 * d.z(), 1e-15);
  EXPECT_NEAR(y[3], c1 * d.x(), 1e-15);
  // y_2^0 = sqrt(5 / (16 pi)) (3 z^2 - 1), y_2^2 = sqrt(15 / (16 pi)) (x^2 - y^2).
  double y3[9];
  prt::sh_eval(3, d, y3);
  EXPECT_NEAR(y3[6], std::sqrt(5.0 / (16 * std::numbers::pi)) * (3 * d.z() * d.z() - 1), 1e-14);
  EXPECT_NEAR(y3[8], std::sqrt(15.0 / (16 * std::numbers::pi)) * (d.x() * d.x() - d.y() * d.y()),
              1e-14);
  EXPECT_NEAR(y3[4], std::sqrt(15.0 / (4 * std::numbers::pi)) * d.x() * d.y(), 1e-14);
}

TEST(Sh, RecurrenceMatchesTextbookFormulaAtOrder10) {
  prt::Pcg32 rng(7);
  double y[100];
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d d = prt::sample_uniform_sphere(rng.next_double(), rng.next_double());
    prt::sh_eval(10, d, y);
    for (int l = 0; l < 10; ++l)
      for (int m = -l; m <= l; ++m)
        ASSERT_NEAR(y[prt::sh_index(l, m)], prt::sh_reference(l, m, d), 1e-12)
            << "l=" << l << " m=" << m;
  }
}

TEST(Sh, FloatAndBatchAgreeWithDouble) {
  prt::Pcg32 rng(3);
  Eigen::Matrix3Xd dirs(3, 64);
  for (int k = 0; k < dirs.cols(); ++k)
    dirs.col(k) = prt::sample_uniform_sphere(rng.next_double(), rng.next_double());
  prt::ShBatchD batch;
  prt::sh_eval_batch(8, dirs, batch);
  prt::ShBatchF batch_f;
  prt::sh_eval_batch(8, Eigen::Matrix3Xf(dirs.cast<float>()), batch_f);
  ASSERT_EQ(batch.rows(), 64);
  double single[64];
  for (int k = 0; k < dirs.cols(); ++k) {
    prt::sh_eval(8, Eigen::Vector3d(dirs.col(k)), single);
    for (int i = 0; i < 64; ++i) {
      // The SIMD and scalar instances contract multiply-adds into FMAs differently, so they
      // agree to rounding, not bit for bit.
      EXPECT_NEAR(batch(i, k), single[i], 1e-14);
      // float keeps ~7 digits; values are O(1), recurrence loses little.
      EXPECT_NEAR(batch_f(i, k), single[i], 2e-5);
    }
  }
}

TEST(Sh, OrthonormalAtOrder10ByQuadrature) {
  // Product quadrature exact for polynomials of degree <= 2*9 in (x, y, z): Gauss-Legendre
  // in z with 12 nodes and 24 equally spaced phi. Max |<y_i, y_j> - delta_ij| < 1e-5; with exact
  // quadrature it is ~1e-14.
  std::vector<double> gx, gw;
  gauss_legendre(12, gx, gw);
  const int nphi = 24;
  const int n = 100;
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(n, n);
  double y[100];
  for (std::size_t i = 0; i < gx.size(); ++i) {
    const double z = gx[i], r = std::sqrt(1 - z * z);
    for (int k = 0; k < nphi; ++k) {
      const double phi = 2 * std::numbers::pi * (k + 0.5) / nphi;
      prt::sh_eval(10, Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z), y);
      const Eigen::Map<Eigen::VectorXd> v(y, n);
      gram += gw[i] * (2 * std::numbers::pi / nphi) * v * v.transpose();
    }
  }
  const double err = (gram - Eigen::MatrixXd::Identity(n, n)).cwiseAbs().maxCoeff();
  EXPECT_LT(err, 1e-5);
}

TEST(Sh, ExpandEvaluatesSeries) {
  Eigen::VectorXd c = Eigen::VectorXd::Zero(9);
  c[prt::sh_index(1, 1)] = 2.0;  // 2 y_1^1 = 2 sqrt(3/4pi) x
  EXPECT_NEAR(prt::sh_expand(c, Eigen::Vector3d(1, 0, 0)),
              2 * std::sqrt(3 / (4 * std::numbers::pi)), 1e-14);
  EXPECT_THROW(prt::sh_expand(Eigen::VectorXd::Zero(5), Eigen::Vector3d::UnitZ()),
               std::invalid_argument);
}

}  // namespace
