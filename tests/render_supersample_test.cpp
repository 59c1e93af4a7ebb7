// Supersampling: the downsample is the block mean (so a half-covered pixel has alpha 0.5),
// and the enlarged camera keeps the view (the same world point lands on the same pixel
// centre once divided by the factor).
#include "render/supersample.h"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

namespace {

TEST(Supersample, BoxDownsampleIsTheBlockMean) {
  render::Image big;
  big.width = 4;
  big.height = 2;
  big.rgba.assign(4 * 2 * 4, 0.f);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      float* p = big.pixel(x, y);
      p[0] = float(x + 4 * y);
      p[3] = x < 1 ? 1.f : 0.f;  // one of the left block's four samples covered
    }
  const render::Image small = render::box_downsample(big, 2);
  ASSERT_EQ(small.width, 2);
  ASSERT_EQ(small.height, 1);
  EXPECT_FLOAT_EQ(small.pixel(0, 0)[0], (0 + 1 + 4 + 5) / 4.f);
  EXPECT_FLOAT_EQ(small.pixel(1, 0)[0], (2 + 3 + 6 + 7) / 4.f);
  EXPECT_FLOAT_EQ(small.pixel(0, 0)[3], 0.5f);
  EXPECT_FLOAT_EQ(small.pixel(1, 0)[3], 0.f);
  EXPECT_THROW(render::box_downsample(big, 3), std::invalid_argument);
}

TEST(Supersample, EnlargedCameraKeepsTheView) {
  render::Camera c;
  c.width = 64;
  c.height = 48;
  const render::Camera s = render::supersampled(c, 3);
  EXPECT_EQ(s.width, 192);
  EXPECT_EQ(s.height, 144);
  EXPECT_DOUBLE_EQ(s.aspect(), c.aspect());
  EXPECT_LE((s.clip_from_world() - c.clip_from_world()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_THROW(render::supersampled(c, 0), std::invalid_argument);
}

}  // namespace
