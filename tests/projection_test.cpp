// Projection of probes to SH: round trips, a point light landing where its pixel says, and
// determinism.
#include "prt/projection.h"

#include "probes/procedural.h"
#include "prt/sampling.h"
#include "prt/sh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

namespace {

prt::ShLighting random_lighting(int order, std::uint64_t seed) {
  prt::Pcg32 rng(seed);
  prt::ShLighting c(prt::sh_count(order), 3);
  for (int i = 0; i < c.rows(); ++i)
    for (int ch = 0; ch < 3; ++ch) c(i, ch) = rng.next_double() * 2 - 1;
  return c;
}

TEST(Projection, ConstantProbeHasOnlyDc) {
  const double dc = std::sqrt(4 * std::numbers::pi);  // L * integral of y_0
  double leak[2];
  for (int k = 0; k < 2; ++k) {
    const int h = 64 << k;
    const prt::ShLighting l =
        prt::project(probes::make_constant(2 * h, h, probes::Rgb(1, 2, 3)), 6);
    // Exact solid angles make the DC term exact up to float texels.
    EXPECT_NEAR(l(0, 0), 1 * dc, 1e-5);
    EXPECT_NEAR(l(0, 1), 2 * dc, 1e-5);
    EXPECT_NEAR(l(0, 2), 3 * dc, 1e-5);
    leak[k] = l.bottomRows(35).cwiseAbs().maxCoeff();
  }
  // Higher bands vanish up to the midpoint rule's error in theta, which is second order:
  // doubling the rows divides it by ~4.
  EXPECT_LT(leak[1], 1e-3);
  EXPECT_NEAR(leak[0] / leak[1], 4.0, 0.2);
}

TEST(Projection, ProjectReconstructRoundTripAtOrder6) {
  // A probe built from order-6 SH reproduces it: max relative error < 1e-3 at 1024 x 512.
  const prt::ShLighting c = random_lighting(6, 42);
  const probes::Probe probe = prt::reconstruct(c, 1024, 512);
  const prt::ShLighting back = prt::project(probe, 6);
  EXPECT_LT((back - c).cwiseAbs().maxCoeff() / c.cwiseAbs().maxCoeff(), 1e-3);
  // Reconstructing again reproduces the texels within the same tolerance.
  const probes::Probe again = prt::reconstruct(back, 1024, 512);
  double max_err = 0, max_val = 0;
  for (std::size_t i = 0; i < probe.texels().size(); ++i) {
    max_err =
        std::max(max_err, double((again.texels()[i] - probe.texels()[i]).cwiseAbs().maxCoeff()));
    max_val = std::max(max_val, double(probe.texels()[i].cwiseAbs().maxCoeff()));
  }
  EXPECT_LT(max_err / max_val, 1e-3);
}

TEST(Projection, SingleBrightPixelLandsAtItsDirection) {
  // A delta of power P at direction d projects to P y(d): the band-1 coefficients point at d.
  const int w = 512, h = 256, x = 300, y = 70;
  std::vector<probes::Rgb> texels(w * h, probes::Rgb::Zero());
  texels[y * w + x] = probes::Rgb::Constant(1000.f);
  const probes::Probe probe(w, h, texels);
  const prt::ShLighting l = prt::project(probe, 3);
  const Eigen::Vector3d d = probe.pixel_direction(x, y);
  // Band 1 in (y, z, x) order.
  const Eigen::Vector3d lobe(l(3, 0), l(1, 0), l(2, 0));
  EXPECT_GT(lobe.normalized().dot(d), 1 - 1e-9);
  const double power = 1000.0 * probe.pixel_solid_angle(y);
  double basis[9];
  prt::sh_eval(3, d, basis);
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(l(i, 1), power * basis[i], 1e-9 * power);
}

TEST(Projection, SunDiscLandsWhereItsPixelSays) {
  const Eigen::Vector3d sun = Eigen::Vector3d(0.6, 0.5, -0.62).normalized();
  const prt::ShLighting l =
      prt::project(probes::make_sun(1024, 512, sun, 0.05, probes::Rgb::Constant(5000.f)), 2);
  const Eigen::Vector3d lobe(l(3, 0), l(1, 0), l(2, 0));
  EXPECT_GT(lobe.normalized().dot(sun), std::cos(0.01));
}

TEST(Projection, IsDeterministic) {
  const probes::Probe probe = prt::reconstruct(random_lighting(4, 9), 256, 128);
  const prt::ShLighting a = prt::project(probe, 8);
  const prt::ShLighting b = prt::project(probe, 8);
  EXPECT_EQ(0, std::memcmp(a.data(), b.data(), sizeof(double) * a.size()));
}

TEST(Projection, RejectsBadOrder) {
  EXPECT_THROW(prt::project(probes::make_constant(16, 8, probes::Rgb::Ones()), 0),
               std::invalid_argument);
  EXPECT_THROW(prt::project(probes::make_constant(16, 8, probes::Rgb::Ones()), 11),
               std::invalid_argument);
}

}  // namespace
