// Zonal kernels against direct numerical integration, and irradiance closed forms.
#include "prt/zonal.h"

#include "probes/procedural.h"
#include "prt/projection.h"
#include "prt/sampling.h"
#include "prt/sh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace {

// h_l = 2 pi int_0^pi h(theta) y_l^0(theta) sin(theta) dtheta by composite Simpson.
double integrate_zonal(int l, double exponent) {
  const int steps = 20000;
  double sum = 0.0;
  for (int k = 0; k <= steps; ++k) {
    const double x = double(k) / steps;  // cos(theta) over [0, 1]; the lobe is 0 below
    const double w = (k == 0 || k == steps) ? 1 : (k % 2 ? 4 : 2);
    sum += w * std::pow(x, exponent) *
           prt::sh_reference(l, 0, Eigen::Vector3d(0, std::sqrt(1 - x * x), x));
  }
  return 2 * std::numbers::pi * sum / (3.0 * steps);
}

TEST(Zonal, ClampedCosineClosedForms) {
  const Eigen::VectorXd h = prt::zonal_clamped_cosine(6);
  EXPECT_NEAR(h[0], std::sqrt(std::numbers::pi) / 2, 1e-14);
  EXPECT_NEAR(h[1], std::sqrt(std::numbers::pi / 3), 1e-14);
  EXPECT_NEAR(h[2], std::sqrt(5 * std::numbers::pi) / 8, 1e-14);
  EXPECT_NEAR(h[3], 0.0, 1e-15);
  EXPECT_NEAR(h[5], 0.0, 1e-15);
}

TEST(Zonal, CosinePowerMatchesQuadrature) {
  for (double s : {0.0, 1.0, 2.5, 10.0, 64.0}) {
    const Eigen::VectorXd h = prt::zonal_cosine_power(10, s);
    for (int l = 0; l < 10; ++l) {
      // Simpson error for smooth integrands at 20000 steps is far below 1e-8, except for
      // non-integer s where x^s is not smooth at 0: 2.5 keeps three derivatives.
      EXPECT_NEAR(h[l], integrate_zonal(l, s), 1e-8) << "s=" << s << " l=" << l;
    }
  }
  EXPECT_THROW(prt::zonal_cosine_power(6, -1.0), std::invalid_argument);
}

TEST(Zonal, PhongLobeIsNormalised) {
  // Integral over the sphere = sqrt(4 pi) * h_0.
  for (double s : {1.0, 8.0, 100.0})
    EXPECT_NEAR(std::sqrt(4 * std::numbers::pi) * prt::zonal_phong(6, s)[0], 1.0, 1e-12);
}

TEST(Zonal, IrradianceOfConstantProbeIsPiL) {
  const probes::Rgb radiance(2.0f, 0.5f, 1.0f);
  // At 512 rows the midpoint rule leaks ~1e-6 relative into bands >= 2 (see
  // Projection.ConstantProbeHasOnlyDc), so 1e-5 relative is a safe bound.
  const prt::ShLighting l = prt::project(probes::make_constant(1024, 512, radiance), 6);
  const Eigen::MatrixXd e = prt::irradiance(l);
  prt::Pcg32 rng(1);
  for (int k = 0; k < 50; ++k) {
    const Eigen::Vector3d n = prt::sample_uniform_sphere(rng.next_double(), rng.next_double());
    for (int ch = 0; ch < 3; ++ch)
      EXPECT_NEAR(prt::sh_expand(e.col(ch), n), std::numbers::pi * radiance[ch],
                  1e-5 * std::numbers::pi * radiance[ch]);
  }
}

TEST(Zonal, IrradianceOfSkyMatchesClosedForm) {
  // Radiance 1 on the upper hemisphere about +Z, 0 below. Irradiance at a normal at angle
  // t from +Z is pi (1 + cos t) / 2. Band-limited to order 10 the cosine convolution keeps
  // the answer within ~1% (the kernel's coefficients above band 2 are small).
  const probes::Probe sky = probes::make_from_function(1024, 512, [](const Eigen::Vector3d& w) {
    return probes::Rgb::Constant(w.z() > 0 ? 1.f : 0.f);
  });
  const Eigen::MatrixXd e = prt::irradiance(prt::project(sky, 10));
  for (double t : {0.0, 0.5, 1.0, 1.5707963, 2.5, 3.14159}) {
    const Eigen::Vector3d n(std::sin(t), 0, std::cos(t));
    EXPECT_NEAR(prt::sh_expand(e.col(0), n), std::numbers::pi * (1 + std::cos(t)) / 2, 0.03)
        << "t=" << t;
  }
}

}  // namespace
