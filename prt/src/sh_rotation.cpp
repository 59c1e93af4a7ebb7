// SH rotation by the Ivanic-Ruedenberg recurrence (J. Phys. Chem. 1996, 100, 6342; corrected
// in J. Phys. Chem. A 1998, 102, 9099). Band l is built from band l-1 and the band-1 matrix,
// which is R itself in the (y, z, x) order of the l = 1 basis functions.
#include "prt/sh_rotation.h"

#include "prt/sh.h"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace prt {
namespace {

// Access band-l block with signed indices m, m' in [-l, l].
struct Band {
  const Eigen::MatrixXd& d;
  int l;
  double operator()(int m, int mp) const { return d(m + l, mp + l); }
};

double kronecker(int a, int b) {
  return a == b ? 1.0 : 0.0;
}

// The paper's P function: i in {-1, 0, 1}, mu a row index of band l-1, mp in [-l, l].
double p_term(int i, int mu, int mp, int l, const Band& r1, const Band& prev) {
  if (mp == l) return r1(i, 1) * prev(mu, l - 1) - r1(i, -1) * prev(mu, -l + 1);
  if (mp == -l) return r1(i, 1) * prev(mu, -l + 1) + r1(i, -1) * prev(mu, l - 1);
  return r1(i, 0) * prev(mu, mp);
}

double u_term(int m, int mp, int l, const Band& r1, const Band& prev) {
  return p_term(0, m, mp, l, r1, prev);
}

double v_term(int m, int mp, int l, const Band& r1, const Band& prev) {
  if (m == 0) return p_term(1, 1, mp, l, r1, prev) + p_term(-1, -1, mp, l, r1, prev);
  if (m > 0) {
    const double d1 = kronecker(m, 1);
    return p_term(1, m - 1, mp, l, r1, prev) * std::sqrt(1.0 + d1) -
           p_term(-1, -m + 1, mp, l, r1, prev) * (1.0 - d1);
  }
  const double d1 = kronecker(m, -1);
  return p_term(1, m + 1, mp, l, r1, prev) * (1.0 - d1) +
         p_term(-1, -m - 1, mp, l, r1, prev) * std::sqrt(1.0 + d1);
}

double w_term(int m, int mp, int l, const Band& r1, const Band& prev) {
  // Only called for m != 0 (its coefficient w vanishes at m = 0).
  if (m > 0) return p_term(1, m + 1, mp, l, r1, prev) + p_term(-1, -m - 1, mp, l, r1, prev);
  return p_term(1, m - 1, mp, l, r1, prev) - p_term(-1, -m + 1, mp, l, r1, prev);
}

// The u, v, w coefficients of the recurrence depend only on (l, m, m'), not on R: computed
// once per band (three square roots per element were ~60% of building D at order 6).
struct Coefficients {
  std::vector<Eigen::ArrayXXd> u, v, w;  // per band l >= 2, indexed (m + l, m' + l)
  Coefficients() : u(kMaxOrder), v(kMaxOrder), w(kMaxOrder) {
    for (int l = 2; l < kMaxOrder; ++l) {
      const int size = 2 * l + 1;
      u[l].resize(size, size);
      v[l].resize(size, size);
      w[l].resize(size, size);
      for (int m = -l; m <= l; ++m) {
        const int am = std::abs(m);
        const double d0 = kronecker(m, 0);
        for (int mp = -l; mp <= l; ++mp) {
          const double denom =
              std::abs(mp) < l ? double(l + mp) * double(l - mp) : double(2 * l) * (2 * l - 1);
          u[l](m + l, mp + l) = std::sqrt(double(l + m) * double(l - m) / denom);
          v[l](m + l, mp + l) =
              0.5 * std::sqrt((1.0 + d0) * double(l + am - 1) * double(l + am) / denom) *
              (1.0 - 2.0 * d0);
          w[l](m + l, mp + l) =
              -0.5 * std::sqrt(double(l - am - 1) * double(l - am) / denom) * (1.0 - d0);
        }
      }
    }
  }
};

const Coefficients& coefficients() {
  static const Coefficients c;
  return c;
}

}  // namespace

ShRotation::ShRotation(int order, const Eigen::Matrix3d& rotation) : order_(order) {
  check_order(order, "SH rotation order");
  bands_.resize(order);
  for (int l = 0; l < order; ++l) bands_[l].resize(2 * l + 1, 2 * l + 1);
  set(rotation);
}

void ShRotation::set(const Eigen::Matrix3d& rotation) {
  const int order = order_;
  const double orth_err =
      (rotation * rotation.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(orth_err < 1e-6) || !(std::abs(rotation.determinant() - 1.0) < 1e-6)) {
    throw std::invalid_argument(
        "ShRotation: matrix is not a rotation (|R R^T - I| = " + std::to_string(orth_err) +
        ", det = " + std::to_string(rotation.determinant()) + ")");
  }
  bands_[0](0, 0) = 1.0;
  if (order == 1) return;

  // Band 1 in the (y, z, x) order of y_1^{-1}, y_1^0, y_1^1.
  const int perm[3] = {1, 2, 0};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) bands_[1](i, j) = rotation(perm[i], perm[j]);
  const Band b1{bands_[1], 1};

  for (int l = 2; l < order; ++l) {
    Eigen::MatrixXd& d = bands_[l];
    const Band prev{bands_[l - 1], l - 1};
    const Coefficients& k = coefficients();
    for (int m = -l; m <= l; ++m) {
      for (int mp = -l; mp <= l; ++mp) {
        const double u = k.u[l](m + l, mp + l);
        const double v = k.v[l](m + l, mp + l);
        const double w = k.w[l](m + l, mp + l);
        double value = 0.0;
        if (u != 0.0) value += u * u_term(m, mp, l, b1, prev);
        if (v != 0.0) value += v * v_term(m, mp, l, b1, prev);
        if (w != 0.0) value += w * w_term(m, mp, l, b1, prev);
        d(m + l, mp + l) = value;
      }
    }
  }
}

Eigen::MatrixXd ShRotation::dense() const {
  const int n = sh_count(order_);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n, n);
  for (int l = 0; l < order_; ++l) out.block(l * l, l * l, 2 * l + 1, 2 * l + 1) = bands_[l];
  return out;
}

Eigen::MatrixXd ShRotation::apply(const Eigen::Ref<const Eigen::MatrixXd>& coefficients) const {
  Eigen::MatrixXd out(coefficients.rows(), coefficients.cols());
  apply(coefficients, out);
  return out;
}

void ShRotation::apply(const Eigen::Ref<const Eigen::MatrixXd>& coefficients,
                       Eigen::Ref<Eigen::MatrixXd> out) const {
  const int n = sh_count(order_);
  if (coefficients.rows() != n || out.rows() != n || out.cols() != coefficients.cols()) {
    throw std::invalid_argument("ShRotation::apply: expected " + std::to_string(n) +
                                " rows (order " + std::to_string(order_) + "), got " +
                                std::to_string(coefficients.rows()));
  }
  for (int l = 0; l < order_; ++l) {
    const int size = 2 * l + 1;
    out.middleRows(l * l, size).noalias() = bands_[l] * coefficients.middleRows(l * l, size);
  }
}

Eigen::Matrix3d axis_angle(const Eigen::Vector3d& axis, double angle_radians) {
  return Eigen::AngleAxisd(angle_radians, axis.normalized()).toRotationMatrix();
}

}  // namespace prt
