// The background shader's atan2 against std::atan2 over a dense sweep of angles and radii:
// the bound render/shader_source.h states is the one measured here.
#include "render/shader_source.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace {

TEST(ShaderSource, Atan2ApproximationMeetsItsStatedBound) {
  constexpr int kAngles = 200000;
  double worst = 0.0;
  for (int i = 0; i <= kAngles; ++i) {
    const double angle = -std::numbers::pi + 2.0 * std::numbers::pi * i / kAngles;
    for (double radius : {1e-3, 1.0, 1e3}) {
      const float y = float(radius * std::sin(angle)), x = float(radius * std::cos(angle));
      const double exact = std::atan2(double(y), double(x));
      double error = std::abs(double(render::atan2_approx(y, x)) - exact);
      error = std::min(error, 2.0 * std::numbers::pi - error);  // -pi and pi are one angle
      worst = std::max(worst, error);
    }
  }
  EXPECT_LE(worst, render::kAtan2MaxError);
  EXPECT_GT(worst, 0.25 * render::kAtan2MaxError) << "the stated bound is loose: " << worst;
  EXPECT_EQ(render::atan2_approx(0.f, 0.f), 0.f);
}

}  // namespace
