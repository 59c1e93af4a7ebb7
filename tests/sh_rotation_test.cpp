// SH rotation: the defining identity y(R w) = D(R) y(w), group properties, and agreement
// with re-projecting a rotated probe.
#include "prt/sh_rotation.h"

#include "probes/procedural.h"
#include "prt/projection.h"
#include "prt/sampling.h"
#include "prt/sh.h"

#include <gtest/gtest.h>

#include <numbers>

namespace {

TEST(ShRotation, DefiningIdentityHoldsAtOrder10) {
  prt::Pcg32 rng(11);
  double y_rot[100], y[100];
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Matrix3d r = prt::random_rotation(rng);
    const prt::ShRotation d(10, r);
    const Eigen::MatrixXd dense = d.dense();
    for (int k = 0; k < 10; ++k) {
      const Eigen::Vector3d w = prt::sample_uniform_sphere(rng.next_double(), rng.next_double());
      prt::sh_eval(10, Eigen::Vector3d(r * w), y_rot);
      prt::sh_eval(10, w, y);
      const Eigen::VectorXd lhs = Eigen::Map<Eigen::VectorXd>(y_rot, 100);
      const Eigen::VectorXd rhs = dense * Eigen::Map<Eigen::VectorXd>(y, 100);
      ASSERT_LT((lhs - rhs).cwiseAbs().maxCoeff(), 1e-10) << "trial " << trial;
    }
  }
}

TEST(ShRotation, ComposesIsOrthogonalAndInverts) {
  prt::Pcg32 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Matrix3d r1 = prt::random_rotation(rng), r2 = prt::random_rotation(rng);
    const Eigen::MatrixXd d1 = prt::ShRotation(6, r1).dense();
    const Eigen::MatrixXd d2 = prt::ShRotation(6, r2).dense();
    const Eigen::MatrixXd d12 = prt::ShRotation(6, r1 * r2).dense();
    EXPECT_LT((d12 - d1 * d2).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_LT((d1 * d1.transpose() - Eigen::MatrixXd::Identity(36, 36)).cwiseAbs().maxCoeff(),
              1e-6);
    EXPECT_LT((prt::ShRotation(6, r1.transpose()).dense() - d1.transpose()).cwiseAbs().maxCoeff(),
              1e-6);
  }
}

TEST(ShRotation, IdentityAndZAxisClosedForm) {
  EXPECT_LT(
      (prt::ShRotation(6, Eigen::Matrix3d::Identity()).dense() - Eigen::MatrixXd::Identity(36, 36))
          .cwiseAbs()
          .maxCoeff(),
      1e-14);
  // About +Z (the polar axis) band l mixes (m, -m) pairs by angle m * alpha.
  const double alpha = 0.7;
  const prt::ShRotation d(4, prt::axis_angle(Eigen::Vector3d::UnitZ(), alpha));
  for (int l = 1; l < 4; ++l) {
    for (int m = 1; m <= l; ++m) {
      EXPECT_NEAR(d.band(l)(l + m, l + m), std::cos(m * alpha), 1e-12);
      EXPECT_NEAR(d.band(l)(l - m, l - m), std::cos(m * alpha), 1e-12);
      EXPECT_NEAR(std::abs(d.band(l)(l + m, l - m)), std::sin(m * alpha), 1e-12);
    }
    EXPECT_NEAR(d.band(l)(l, l), 1.0, 1e-12);
  }
}

TEST(ShRotation, ApplyMatchesDenseProduct) {
  prt::Pcg32 rng(2);
  const prt::ShRotation d(6, prt::random_rotation(rng));
  const Eigen::MatrixXd l = Eigen::MatrixXd::Random(36, 3);
  EXPECT_LT((d.apply(l) - d.dense() * l).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_THROW(d.apply(Eigen::MatrixXd::Zero(25, 3)), std::invalid_argument);
}

TEST(ShRotation, RejectsNonRotation) {
  EXPECT_THROW(prt::ShRotation(6, -Eigen::Matrix3d::Identity()), std::invalid_argument);
  EXPECT_THROW(prt::ShRotation(6, 2 * Eigen::Matrix3d::Identity()), std::invalid_argument);
  EXPECT_THROW(prt::ShRotation(11, Eigen::Matrix3d::Identity()), std::invalid_argument);
}

TEST(ShRotation, RotatingCoefficientsEqualsProjectingTheRotatedProbe) {
  // f is an order-6 SH function; g(w) = f(R^-1 w) is built by evaluating f at rotated
  // directions (no image resampling). Its projection must equal D(R) c up to the
  // projection's own quadrature error, which we measure on f itself (the same 1024 x 512
  // grid) and which must stay < 1e-3 relative.
  prt::Pcg32 rng(19);
  const int order = 6, n = 36;
  prt::ShLighting c(n, 3);
  for (int i = 0; i < n; ++i)
    for (int ch = 0; ch < 3; ++ch) c(i, ch) = rng.next_double() * 2 - 1;
  auto eval = [&](const Eigen::Vector3d& w) {
    double y[36];
    prt::sh_eval(order, w, y);
    const Eigen::Vector3d v = Eigen::Map<Eigen::VectorXd>(y, n).transpose() * c;
    return probes::Rgb(v.cast<float>());
  };
  const prt::ShLighting c_back = prt::project(probes::make_from_function(1024, 512, eval), order);
  const double quad_err = (c_back - c).norm() / c.norm();
  EXPECT_LT(quad_err, 1e-3);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::Matrix3d r = prt::random_rotation(rng);
    const probes::Probe rotated = probes::make_from_function(
        1024, 512, [&](const Eigen::Vector3d& w) { return eval(r.transpose() * w); });
    const prt::ShLighting projected = prt::project(rotated, order);
    const prt::ShLighting turned = prt::ShRotation(order, r).apply(c);
    const double err = (projected - turned).norm() / turned.norm();
    // Float texels add ~1e-7; allow 3x the measured quadrature error plus that.
    EXPECT_LT(err, 3 * quad_err + 1e-6) << "trial " << trial << " quad_err " << quad_err;
    EXPECT_LT(err, 1e-3);
  }
}

}  // namespace
