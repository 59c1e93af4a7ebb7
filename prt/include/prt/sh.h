// prt/sh.h: real spherical harmonics, evaluated by recurrence.
//
// Conventions (the engine's only ones; every module uses these functions):
//  - Real, orthonormal SH over the unit sphere: integral of y_i y_j over S^2 = delta_ij.
//  - Order N means bands l = 0 .. N-1, so n = N^2 coefficients. Supported orders 1 .. 10.
//  - Flat index i = l (l + 1) + m, for -l <= m <= l (l first, then m ascending).
//  - The polar axis is +Z of whatever frame the direction is given in (theta from +Z, phi
//    from +X toward +Y). In a vertex's local frame +Z is the normal; in the world frame the
//    polar axis is world +Z, not the +Y up axis; nothing depends on that choice because
//    lighting and transfer are always expressed in the same frame.
//  - No Condon-Shortley phase: y_1 = sqrt(3 / 4 pi) (y, z, x) for m = -1, 0, 1. This is the
//    basis Ivanic & Ruedenberg's rotation recurrence is written for (prt/sh_rotation.h).
//    y_l^m = sqrt(2) K_l^m P_l^|m|(cos theta) cos(m phi)   for m > 0
//          = sqrt(2) K_l^|m| P_l^|m|(cos theta) sin(|m| phi) for m < 0
//          = K_l^0 P_l^0(cos theta)                           for m = 0
//    with K_l^m = sqrt((2l + 1) / (4 pi) (l - m)! / (l + m)!) and P_l^m without the
//    (-1)^m phase.
//
// The fast path folds sin^m(theta) into Re/Im (x + i y)^m so it needs no trigonometry and no
// allocation; sh_reference() evaluates the textbook formula with std::assoc_legendre and
// std::atan2, and a test makes the two agree.
#pragma once

#include <Eigen/Core>

#include <cstddef>

namespace prt {

inline constexpr int kMinOrder = 1;
inline constexpr int kMaxOrder = 10;

constexpr int sh_count(int order) {
  return order * order;
}
constexpr int sh_index(int l, int m) {
  return l * (l + 1) + m;
}
// Band of a flat index: the largest l with l^2 <= i.
int sh_band(int index);

// Throws std::invalid_argument naming `what` when order is outside [kMinOrder, kMaxOrder].
void check_order(int order, const char* what = "order");

// All sh_count(order) basis values at the unit direction (x, y, z), written to out[0 .. n).
// Precondition: x^2 + y^2 + z^2 == 1 (not checked; the result scales with |d|^l otherwise).
void sh_eval(int order, double x, double y, double z, double* out);
void sh_eval(int order, float x, float y, float z, float* out);

inline void sh_eval(int order, const Eigen::Vector3d& d, double* out) {
  sh_eval(order, d.x(), d.y(), d.z(), out);
}

// Batched: column k of `out` (n x count) holds the basis at column k of `directions`
// (3 x count). Row-major, so each basis function is contiguous over directions: the
// evaluation writes whole SIMD vectors, and projections Y W Y^T are plain GEMMs either way.
// `out` is resized only when its shape differs, so reusing it does not allocate.
using ShBatchF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using ShBatchD = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
void sh_eval_batch(int order, const Eigen::Ref<const Eigen::Matrix3Xf>& directions, ShBatchF& out);
void sh_eval_batch(int order, const Eigen::Ref<const Eigen::Matrix3Xd>& directions, ShBatchD& out);

// Textbook evaluation of one basis function (slow; the oracle for the tests).
double sh_reference(int l, int m, const Eigen::Vector3d& direction);

// Value of the SH expansion `coefficients` (n entries, any order <= 10) at `direction`.
double sh_expand(const Eigen::Ref<const Eigen::VectorXd>& coefficients,
                 const Eigen::Vector3d& direction);

}  // namespace prt
