// prt/zonal.h: zonal (rotationally symmetric about +Z) kernels and convolution with them.
//
// A zonal function h(cos theta) has only m = 0 coefficients; zonal_*() return h_l, the
// coefficient of y_l^0, for l = 0 .. order-1. Convolving a spherical function f with h
// (integrating f against h rotated to point along each direction n) scales band l by
// sqrt(4 pi / (2l + 1)) h_l (Funk-Hecke). For the clamped cosine this gives irradiance:
// E(n) = sum_lm sqrt(4 pi / (2l + 1)) h_l f_lm y_lm(n); a constant f = L gives E = pi L.
#pragma once

#include <Eigen/Core>

namespace prt {

// Coefficients of max(0, cos theta)^s, s >= 0 (s = 1 is the clamped cosine). Computed from
// the exact recurrence (s + l + 1) I_l = (s - l + 2) I_{l-2} for I_l = int_0^1 P_l(x) x^s dx.
Eigen::VectorXd zonal_cosine_power(int order, double exponent);

// Lambert: max(0, cos theta).
Eigen::VectorXd zonal_clamped_cosine(int order);

// Normalised Phong lobe (s + 1) / (2 pi) max(0, cos theta)^s: integrates to 1 over the
// sphere, so convolving a constant L with it gives L.
Eigen::VectorXd zonal_phong(int order, double exponent);

// Convolution: row block of band l of `coefficients` (n x k) times sqrt(4 pi/(2l+1)) h_l.
Eigen::MatrixXd zonal_convolve(const Eigen::Ref<const Eigen::MatrixXd>& coefficients,
                               const Eigen::Ref<const Eigen::VectorXd>& kernel);

// Irradiance coefficients from radiance coefficients (n x 3): convolution with the clamped
// cosine. Evaluate with sh_expand at the normal.
Eigen::MatrixXd irradiance(const Eigen::Ref<const Eigen::MatrixXd>& radiance);

}  // namespace prt
