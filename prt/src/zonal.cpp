// Zonal harmonics of cosine powers. I_l = int_0^1 P_l(x) x^s dx satisfies
// (s + l + 1) I_l = (s - l + 2) I_{l-2}, I_0 = 1/(s+1), I_1 = 1/(s+2) (integrate
// x^s times Bonnet's recurrence by parts); h_l = 2 pi sqrt((2l+1)/(4 pi)) I_l.
#include "prt/zonal.h"

#include "prt/sh.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace prt {

Eigen::VectorXd zonal_cosine_power(int order, double exponent) {
  check_order(order, "zonal kernel order");
  if (!(exponent >= 0.0) || !std::isfinite(exponent)) {
    throw std::invalid_argument("cosine-power exponent must be finite and >= 0, got " +
                                std::to_string(exponent));
  }
  Eigen::VectorXd integral(order);
  for (int l = 0; l < order; ++l) {
    if (l == 0) {
      integral[l] = 1.0 / (exponent + 1.0);
    } else if (l == 1) {
      integral[l] = 1.0 / (exponent + 2.0);
    } else {
      integral[l] = (exponent - l + 2.0) / (exponent + l + 1.0) * integral[l - 2];
    }
  }
  Eigen::VectorXd h(order);
  for (int l = 0; l < order; ++l) {
    h[l] = 2.0 * std::numbers::pi * std::sqrt((2.0 * l + 1.0) / (4.0 * std::numbers::pi)) *
           integral[l];
  }
  return h;
}

Eigen::VectorXd zonal_clamped_cosine(int order) {
  return zonal_cosine_power(order, 1.0);
}

Eigen::VectorXd zonal_phong(int order, double exponent) {
  return (exponent + 1.0) / (2.0 * std::numbers::pi) * zonal_cosine_power(order, exponent);
}

Eigen::MatrixXd zonal_convolve(const Eigen::Ref<const Eigen::MatrixXd>& coefficients,
                               const Eigen::Ref<const Eigen::VectorXd>& kernel) {
  const int order = static_cast<int>(kernel.size());
  if (coefficients.rows() != sh_count(order)) {
    throw std::invalid_argument("zonal_convolve: " + std::to_string(coefficients.rows()) +
                                " coefficient rows do not match a kernel of order " +
                                std::to_string(order));
  }
  Eigen::MatrixXd out = coefficients;
  for (int l = 0; l < order; ++l) {
    out.middleRows(l * l, 2 * l + 1) *=
        std::sqrt(4.0 * std::numbers::pi / (2.0 * l + 1.0)) * kernel[l];
  }
  return out;
}

Eigen::MatrixXd irradiance(const Eigen::Ref<const Eigen::MatrixXd>& radiance) {
  const int order = sh_band(static_cast<int>(radiance.rows()) - 1) + 1;
  return zonal_convolve(radiance, zonal_clamped_cosine(order));
}

}  // namespace prt
