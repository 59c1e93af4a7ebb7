// prt/sh_rotation.h: rotation matrices for real SH (the basis of prt/sh.h).
//
// ShRotation(R) holds D(R), block diagonal with one (2l+1) x (2l+1) block per band, such that
//     y(R w) = D(R) y(w)        for every unit direction w,
// so an SH function f with coefficients c, rotated to g(w) = f(R^-1 w), has coefficients
// D(R) c. D is orthogonal, D(R^T) = D(R)^T, and D(R1 R2) = D(R1) D(R2).
//
// Built by the recurrence of Ivanic & Ruedenberg, "Rotation Matrices for Real Spherical
// Harmonics. Direct Determination by Recursion", J. Phys. Chem. 100 (1996) 6342, with the
// corrections of J. Phys. Chem. A 102 (1998) 9099 (the u, v, w coefficients and the
// P-function cases for |m'| = l as corrected there). Cost is O(N^4) scalar work, ~10 us at
// order 6, so a frame can rebuild it freely.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace prt {

class ShRotation {
 public:
  // `rotation` must be orthogonal with determinant +1 (checked to 1e-6; throws
  // std::invalid_argument otherwise).
  ShRotation(int order, const Eigen::Matrix3d& rotation);

  // Recomputes D for another rotation in place, reusing the band storage (no allocation);
  // same preconditions as the constructor.
  void set(const Eigen::Matrix3d& rotation);

  int order() const { return order_; }
  // Block of band l, size (2l+1)^2, rows/columns ordered m = -l .. l.
  const Eigen::MatrixXd& band(int l) const { return bands_[l]; }
  // The full n x n matrix (zeros off the band blocks).
  Eigen::MatrixXd dense() const;

  // D * coefficients, band by band, for any number of columns (an n x 3 RGB lighting matrix,
  // or an n x n transfer matrix). The row count must be sh_count(order()).
  Eigen::MatrixXd apply(const Eigen::Ref<const Eigen::MatrixXd>& coefficients) const;
  // The same into a caller-owned matrix of the right shape (no allocation).
  void apply(const Eigen::Ref<const Eigen::MatrixXd>& coefficients,
             Eigen::Ref<Eigen::MatrixXd> out) const;

 private:
  int order_;
  std::vector<Eigen::MatrixXd> bands_;
};

// Rotation by `angle_radians` about the unit `axis` (right-hand rule).
Eigen::Matrix3d axis_angle(const Eigen::Vector3d& axis, double angle_radians);

}  // namespace prt
