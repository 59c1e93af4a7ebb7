// prt/view_fit.h: how the view side of a glossy BRDF matrix represents exit radiance.
//
// Exit radiance toward the local direction v is y(v)^T B l. Only views above the local
// horizon (v.z >= 0) are ever evaluated, so how the n = N^2 view functions behave below it is
// free. The fits differ in what they ask of the lower hemisphere; with g_j(v) =
// int f_r(v, s) s.z y_j(s) ds (the exit radiance of light y_j):
//  - hemisphere (the thesis): B_ij = int_{v.z>0} y_i g_j, the SH projection of a function that
//    steps to zero at the horizon. Its series converges like a step's Legendre series at its
//    end point: the value toward the normal alternates in sign from order to order (Lambert:
//    +15.6% at order 6), and the error decays slowly.
//  - even: g extended below the horizon by its mirror image, g(x, y, -z) = g(x, y, z), and
//    projected; only rows with l + m even survive (twice the hemisphere projection). No step,
//    a kink at the horizon; half the rows carry nothing.
//  - least-squares (the default): the B that minimises
//        int_{v.z>0} |y^T B_j - g_j|^2 + lambda int_{S^2} |grad (y^T B_j)|^2
//    over all n view functions: a least-squares fit over the upper hemisphere, made unique
//    and well conditioned by asking the whole function, its free extension below the horizon
//    included, to be smooth. The gradient energy of an SH expansion is sum l (l + 1) c_i^2,
//    so with G the upper-hemisphere Gram matrix and L = diag(l (l + 1)),
//    B = (G + lambda L)^-1 B_hemisphere. A constant costs no gradient energy, so Lambert's
//    exit radiance is reproduced exactly.
//  - hemispherical harmonics (Gautron, Krivanek, Pattanaik & Bouatouch, "A novel hemispherical
//    basis for accurate modeling of BRDFs", EGSR 2004): an orthonormal basis of the upper
//    hemisphere, H_l^m(theta, phi) = sqrt(2) y_l^m(theta', phi) with cos theta' =
//    2 cos theta - 1. It needs a different view basis in every evaluator, and its m != 0
//    functions vanish at the horizon, so grazing views lose their azimuthal variation.
// The measurements behind the default are in docs/ARCHITECTURE.md ("The view side").
#pragma once

#include "common/enum_names.h"

#include <Eigen/Core>

#include <cmath>
#include <string>

namespace prt {

enum class ViewFit { kHemisphere, kEven, kLeastSquares, kHemisphericalHarmonics };

inline constexpr ViewFit kDefaultViewFit = ViewFit::kLeastSquares;
// lambda of the least-squares fit: the weight of the gradient energy.
inline constexpr double kViewFitLambda = 1e-3;

inline constexpr auto kViewFitNames =
    common::enum_table<ViewFit>("view fit", {{ViewFit::kHemisphere, "hemisphere"},
                                             {ViewFit::kEven, "even"},
                                             {ViewFit::kLeastSquares, "least-squares"},
                                             {ViewFit::kHemisphericalHarmonics, "hsh"}});
// Whether the renderers evaluate this fit's view basis: every fit whose basis is the SH
// (all but hemispherical harmonics, which only the benchmarks evaluate).
bool view_fit_renderable(ViewFit fit);

// The view-side projection for a quadrature over the upper hemisphere: an n x count matrix P
// with B = P F, where F (count x n) holds g_j at the `directions` (3 x count, v.z > 0) and
// `weights` are their solid angles. The grid must integrate products of two order-N view
// functions exactly (the Gram matrix comes from it).
Eigen::MatrixXd view_projection(ViewFit fit, int order, const Eigen::Matrix3Xd& directions,
                                const Eigen::VectorXd& weights, double lambda = kViewFitLambda);

// The view basis (n values) at the local unit direction v, v.z >= 0: the SH, or for
// hemispherical harmonics the SH at the remapped direction times sqrt(2).
void view_basis_eval(ViewFit fit, int order, const Eigen::Vector3d& v, double* out);

// The view clamped to the closed upper hemisphere: v itself when v.z >= 0, else v pushed up
// onto the horizon (its tangent part, normalised). A vertex normal at a silhouette or a hit
// corner seen from below its own tangent plane still gets the radiance of its most grazing
// view instead of the fit's extension below the horizon. (0, 0, -1) maps to (1, 0, 0).
template <class Vec3>
Vec3 clamp_to_horizon(const Vec3& v) {
  if (v.z() >= 0) return v;
  const auto t = std::sqrt(v.x() * v.x() + v.y() * v.y());
  if (!(t > 0)) return Vec3(1, 0, 0);
  return Vec3(v.x() / t, v.y() / t, 0);
}

}  // namespace prt
