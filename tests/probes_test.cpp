// tests/probes_test.cpp: the direction <-> pixel convention, lookups, solid angles and
// statistics of probes/probe.h against closed forms; procedural probes; the loader against
// files written here with OpenImageIO and against Blender's real studio-light probes.
#include "probes/load.h"
#include "probes/probe.h"
#include "probes/procedural.h"
#include "test_support.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace probes {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

// Float texels of values up to ~3, blended with float bilinear weights: a few roundings of
// 2.4e-7 each stay below this.
constexpr double kFloatStorage = 2e-6;

// --- Helpers ---------------------------------------------------------------------------------

fs::path tmp_dir() {
  const fs::path dir = fs::path(PRTR_TEST_TMPDIR) / "probes";
  fs::create_directories(dir);
  return dir;
}

// Writes `data` (w * h * channels floats, row-major from the top) with OpenImageIO; the
// format follows the extension. `stored` is the file's pixel type.
void write_image(const fs::path& path, int w, int h, int channels, const std::vector<float>& data,
                 OIIO::TypeDesc stored = OIIO::TypeDesc::FLOAT) {
  ASSERT_EQ(data.size(), std::size_t(w) * h * channels);
  auto out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out) << OIIO::geterror();
  OIIO::ImageSpec spec(w, h, channels, stored);
  ASSERT_TRUE(out->open(path.string(), spec)) << out->geterror();
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, data.data())) << out->geterror();
  ASSERT_TRUE(out->close());
}

// The message of the ProbeError `f` throws ("" and a test failure if it throws none).
std::string error_of(const std::function<void()>& f) {
  return test_support::message_of<ProbeError>(f);
}

Eigen::Vector3d random_direction(std::mt19937& rng) {
  std::normal_distribution<double> n;
  Eigen::Vector3d d;
  do {
    d = {n(rng), n(rng), n(rng)};
  } while (d.norm() < 1e-6);
  return d.normalized();
}

void expect_near3(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tol) {
  EXPECT_NEAR(a.x(), b.x(), tol);
  EXPECT_NEAR(a.y(), b.y(), tol);
  EXPECT_NEAR(a.z(), b.z(), tol);
}

// --- Convention ------------------------------------------------------------------------------

TEST(Convention, NamedDirections) {
  constexpr double kTol = 1e-15;
  expect_near3(latlong_direction(0.5, 0.5), {0, 0, -1}, kTol);   // image centre: -Z
  expect_near3(latlong_direction(0.75, 0.5), {1, 0, 0}, kTol);   // right of centre: +X
  expect_near3(latlong_direction(0.25, 0.5), {-1, 0, 0}, kTol);  // left of centre: -X
  expect_near3(latlong_direction(0.0, 0.5), {0, 0, 1}, kTol);    // seam: +Z
  expect_near3(latlong_direction(1.0, 0.5), {0, 0, 1}, kTol);
  for (double u : {0.0, 0.3, 0.75}) {
    expect_near3(latlong_direction(u, 0.0), {0, 1, 0}, kTol);   // top row: up
    expect_near3(latlong_direction(u, 1.0), {0, -1, 0}, kTol);  // bottom row: down
  }
}

TEST(Convention, UvOfNamedDirections) {
  constexpr double kTol = 1e-15;
  EXPECT_NEAR(latlong_uv({0, 0, -1}).x(), 0.5, kTol);
  EXPECT_NEAR(latlong_uv({1, 0, 0}).x(), 0.75, kTol);
  EXPECT_NEAR(latlong_uv({-1, 0, 0}).x(), 0.25, kTol);
  EXPECT_EQ(latlong_uv({0, 0, 1}).x(), 0.0);
  EXPECT_NEAR(latlong_uv({0, 0, 1}).y(), 0.5, kTol);
  // Poles: v exactly 0 or 1 and u a valid value.
  for (const Eigen::Vector3d& pole : {Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, -1, 0)}) {
    const Eigen::Vector2d uv = latlong_uv(pole);
    EXPECT_GE(uv.x(), 0.0);
    EXPECT_LT(uv.x(), 1.0);
    EXPECT_EQ(uv.y(), pole.y() > 0 ? 0.0 : 1.0);
  }
  // Not unit length: the same answer.
  EXPECT_NEAR(latlong_uv({7, 0, 0}).x(), 0.75, kTol);
  EXPECT_NEAR(latlong_uv({0, 0.001, 0}).y(), 0.0, kTol);
  // Just below the seam on the -X side of +Z: u is in [0, 1), never 1.
  const Eigen::Vector2d seam = latlong_uv({1e-300, 0, 1});
  EXPECT_GE(seam.x(), 0.0);
  EXPECT_LT(seam.x(), 1.0);
}

TEST(Convention, UvInvertsDirection) {
  std::mt19937 rng(1);
  for (int i = 0; i < 10000; ++i) {
    const Eigen::Vector3d d = random_direction(rng);
    const Eigen::Vector2d uv = latlong_uv(d);
    ASSERT_GE(uv.x(), 0.0);
    ASSERT_LT(uv.x(), 1.0);
    ASSERT_GE(uv.y(), 0.0);
    ASSERT_LE(uv.y(), 1.0);
    const Eigen::Vector3d back = latlong_direction(uv.x(), uv.y());
    ASSERT_LT((back - d).norm(), 1e-9) << d.transpose();
    // And the other way round, for (u, v) away from the poles where u is defined.
    const double u = std::uniform_real_distribution<double>(0, 1)(rng);
    const double v = std::uniform_real_distribution<double>(1e-3, 1 - 1e-3)(rng);
    const Eigen::Vector2d uv2 = latlong_uv(latlong_direction(u, v) * 3.0);
    ASSERT_NEAR(uv2.y(), v, 1e-9);
    const double du = std::abs(uv2.x() - u);
    ASSERT_LT(std::min(du, 1 - du), 1e-9);
  }
}

TEST(Convention, RightHandedAndNotMirrored) {
  // Moving right in the image (increasing u) at the horizon, seen from inside looking at the
  // image centre (-Z) with +Y up, must turn toward +X: the camera's right is +X for a
  // right-handed frame looking down -Z. A mirrored map would turn toward -X.
  const Eigen::Vector3d centre = latlong_direction(0.5, 0.5);
  const Eigen::Vector3d right = latlong_direction(0.51, 0.5);
  const Eigen::Vector3d below = latlong_direction(0.5, 0.51);
  EXPECT_GT(right.x(), 0.0);
  EXPECT_LT(below.y(), 0.0);
  // (right - centre) x (up) should point back toward the viewer (+Z) for a non-mirrored view.
  EXPECT_GT((right - centre).cross(Eigen::Vector3d::UnitY()).z(), 0.0);
}

// --- One bright pixel ------------------------------------------------------------------------

Probe black_with_bright(int w, int h, int bx, int by, const Rgb& value) {
  std::vector<Rgb> rgb(std::size_t(w) * h, Rgb::Zero());
  rgb[std::size_t(by) * w + bx] = value;
  return Probe(w, h, std::move(rgb), "bright");
}

TEST(BrightPixel, LandsWhereTheConventionSays) {
  const int w = 64, h = 32, bx = 13, by = 9;
  const Rgb bright(100, 200, 300);
  const Probe p = black_with_bright(w, h, bx, by, bright);
  const Eigen::Vector3d d = p.pixel_direction(bx, by);
  // The convention of probes/probe.h written out here, not through latlong_direction:
  // theta from +Y, phi = 2 pi u, d = (-sin theta sin phi, cos theta, sin theta cos phi).
  const double theta = std::numbers::pi * (by + 0.5) / h,
               phi = 2 * std::numbers::pi * (bx + 0.5) / w;
  expect_near3(d,
               {-std::sin(theta) * std::sin(phi), std::cos(theta), std::sin(theta) * std::cos(phi)},
               1e-15);
  EXPECT_NEAR(d.norm(), 1.0, 1e-15);
  EXPECT_EQ(p.lookup_nearest(d), bright);
  EXPECT_EQ(p.lookup(d), bright);  // exactly at a pixel centre: no blending
  // Half a pixel away in u: halfway between centres, so half the value (bilinear).
  constexpr float kBlend = 1e-4f;  // float weights from double coordinates
  const Eigen::Vector3d du = latlong_direction((bx + 1.0) / w, (by + 0.5) / h);
  EXPECT_TRUE(p.lookup(du).isApprox(0.5f * bright, kBlend)) << p.lookup(du).transpose();
  const Eigen::Vector3d dv = latlong_direction((bx + 0.5) / w, (by + 0.0) / h);
  EXPECT_TRUE(p.lookup(dv).isApprox(0.5f * bright, kBlend)) << p.lookup(dv).transpose();
  // Half a pixel diagonally: a quarter.
  const Eigen::Vector3d duv = latlong_direction((bx + 0.0) / w, (by + 1.0) / h);
  EXPECT_TRUE(p.lookup(duv).isApprox(0.25f * bright, kBlend)) << p.lookup(duv).transpose();
  // A quarter pixel away in u: three quarters.
  const Eigen::Vector3d dq = latlong_direction((bx + 0.75) / w, (by + 0.5) / h);
  EXPECT_TRUE(p.lookup(dq).isApprox(0.75f * bright, kBlend)) << p.lookup(dq).transpose();
  // One full pixel away: the neighbour's centre, black.
  EXPECT_EQ(p.lookup(p.pixel_direction(bx + 1, by)), Rgb::Zero());
  EXPECT_EQ(p.lookup_nearest(p.pixel_direction(bx, by + 1)), Rgb::Zero());
  // The nearest lookup covers the whole pixel: directions just inside its corners.
  for (double ox : {0.01, 0.99}) {
    for (double oy : {0.01, 0.99}) {
      EXPECT_EQ(p.lookup_nearest(latlong_direction((bx + ox) / w, (by + oy) / h)), bright);
    }
  }
}

TEST(BrightPixel, WorldMeaning) {
  // W = 66, H = 33: pixel (49, 16) has its centre exactly at u = 0.75, v = 0.5.
  const int w = 66, h = 33, bx = 49, by = 16;
  ASSERT_EQ((bx + 0.5) / w, 0.75);
  ASSERT_EQ((by + 0.5) / h, 0.5);
  const Rgb bright(5, 5, 5);
  const Probe p = black_with_bright(w, h, bx, by, bright);
  expect_near3(p.pixel_direction(bx, by), {1, 0, 0}, 1e-15);
  EXPECT_EQ(p.lookup_nearest({1, 0, 0}), bright);
  EXPECT_EQ(p.lookup({1, 0, 0}), bright);
  for (const Eigen::Vector3d& other :
       {Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1),
        Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, -1, 0)}) {
    EXPECT_EQ(p.lookup_nearest(other), Rgb::Zero()) << other.transpose();
    EXPECT_EQ(p.lookup(other), Rgb::Zero()) << other.transpose();
  }
}

TEST(BrightPixel, WrapsAcrossTheSeam) {
  // Bright pixel in the last column: a lookup at u = 0 (the seam) lies halfway between the
  // last column's centre and the first column's centre.
  const int w = 32, h = 16;
  const Rgb bright(8, 8, 8);
  const Probe p = black_with_bright(w, h, w - 1, 5, bright);
  const Eigen::Vector3d seam = latlong_direction(0.0, (5 + 0.5) / h);
  EXPECT_TRUE(p.lookup(seam).isApprox(0.5f * bright, 1e-4f)) << p.lookup(seam).transpose();
  EXPECT_EQ(p.lookup_nearest(seam), Rgb::Zero());  // u = 0 belongs to column 0
  EXPECT_EQ(p.lookup_nearest(latlong_direction(1.0 - 1e-9, (5 + 0.5) / h)), bright);
}

TEST(BrightPixel, ClampsAtThePoles) {
  // Above the top row's centres the lookup uses the top row only (clamped in v).
  const int w = 32, h = 16;
  const Rgb bright(4, 4, 4);
  const Probe p = black_with_bright(w, h, 7, 0, bright);
  EXPECT_EQ(p.lookup(latlong_direction((7 + 0.5) / w, 0.2 / h)), bright);
  EXPECT_EQ(p.lookup_nearest({0, 1, 0}), p.texel(0, 0));  // the pole: u = 0, row 0
  const Probe q = black_with_bright(w, h, 0, h - 1, bright);
  EXPECT_EQ(q.lookup_nearest({0, -1, 0}), bright);  // v = 1 belongs to the bottom row
}

// --- Solid angles ----------------------------------------------------------------------------

TEST(SolidAngle, SumsToFourPi) {
  for (int h : {1, 3, 32, 512}) {
    const Probe p = make_constant(2 * h, h, Rgb::Ones());
    double sum = 0.0;
    for (int y = 0; y < h; ++y) sum += p.width() * p.pixel_solid_angle(y);
    EXPECT_NEAR(sum / (4 * kPi), 1.0, 1e-6) << "h = " << h;
  }
}

TEST(SolidAngle, RowIsASphericalBand) {
  for (int h : {3, 32, 512}) {
    const Probe p = make_constant(2 * h, h, Rgb::Ones());
    for (int y = 0; y < h; ++y) {
      // Area of the band between polar angles a and b: 2 pi (cos a - cos b).
      const double a = kPi * y / h, b = kPi * (y + 1) / h;
      const double band = 2 * kPi * (std::cos(a) - std::cos(b));
      // The direct difference of cosines loses ~eps / (band width)^2 relatively at the
      // poles of the 512-row map (about 1e-11); the tolerance covers that.
      EXPECT_NEAR(p.width() * p.pixel_solid_angle(y), band, 1e-9 * band) << h << " " << y;
      EXPECT_GT(p.pixel_solid_angle(y), 0.0);
    }
    // Symmetric about the equator.
    EXPECT_NEAR(p.pixel_solid_angle(0), p.pixel_solid_angle(h - 1), 1e-14 * p.pixel_solid_angle(0));
  }
}

// --- Statistics ------------------------------------------------------------------------------

TEST(Statistics, ConstantProbe) {
  const Rgb c(0.5f, 2.0f, 1234.5f);
  const Probe p = make_constant(64, 32, c);
  // Sum of solid angles is 4 pi to ~1e-15; accumulated in double, rounded once to float.
  EXPECT_TRUE(p.mean_radiance().isApprox(c, 1e-6f)) << p.mean_radiance().transpose();
  EXPECT_EQ(p.max_texel(), c);
}

TEST(Statistics, MaxIsPerChannel) {
  std::vector<Rgb> rgb(8 * 4, Rgb::Zero());
  rgb[3] = {5, 1, 0};
  rgb[20] = {1, 7, -2};
  rgb[31] = {0, 0, 3};
  const Probe p(8, 4, rgb);
  EXPECT_EQ(p.max_texel(), Rgb(5, 7, 3));
  const Probe negative = make_constant(8, 4, Rgb(-1, -2, -3));
  EXPECT_EQ(negative.max_texel(), Rgb(-1, -2, -3));
}

TEST(Statistics, MeanIsSolidAngleWeighted) {
  // f(d) = d.y^2 has mean 1/3 over the sphere; an unweighted pixel mean would give ~1/2.
  // Midpoint rule per row in cos(theta) of a smooth function: error O(1/H^2); 1e-3 at H = 64.
  const Probe p = make_from_function(
      128, 64, [](const Eigen::Vector3d& d) { return Rgb::Constant(float(d.y() * d.y())); });
  EXPECT_NEAR(p.mean_radiance().x(), 1.0 / 3.0, 1e-3);
  // A probe bright only in the upper hemisphere: mean = half the value.
  const Probe upper = make_from_function(
      128, 64, [](const Eigen::Vector3d& d) { return Rgb::Constant(d.y() > 0 ? 2.0f : 0.0f); });
  EXPECT_NEAR(upper.mean_radiance().x(), 1.0, 1e-6);  // the rows split exactly at the equator
}

TEST(Statistics, SunDisc) {
  // A pixel is in the disc when its centre is; every point misclassified by that rule lies
  // within delta of the disc's edge, delta = the largest angle between a pixel's centre and
  // its corners, below (pi / H) / sqrt(2) (half the diagonal at the equator, less elsewhere).
  // So |pixelised area - true area| <= area of the band r +- delta.
  const Rgb radiance(1000, 2000, 3000);
  const int h = 128, w = 2 * h;
  const double delta = (kPi / h) / std::sqrt(2.0) * 1.01;
  struct Case {
    Eigen::Vector3d direction;
    double radius;
  };
  for (const Case& c : {Case{{1, 0.3, -0.5}, 0.2}, Case{{0, 1, 0}, 0.1}, Case{{0.2, -0.1, 1}, 0.05},
                        Case{{-1, 0.8, 0.2}, 0.5}}) {
    const Probe p = make_sun(w, h, c.direction, c.radius, radiance);
    const double area = 2 * kPi * (1 - std::cos(c.radius));
    const double bound =
        2 * kPi * (std::cos(std::max(0.0, c.radius - delta)) - std::cos(c.radius + delta));
    for (int ch = 0; ch < 3; ++ch) {
      EXPECT_NEAR(p.mean_radiance()[ch], radiance[ch] * area / (4 * kPi),
                  radiance[ch] * bound / (4 * kPi))
          << "radius " << c.radius;
    }
    EXPECT_EQ(p.lookup_nearest(c.direction), radiance);
    EXPECT_EQ(p.lookup_nearest(-c.direction), Rgb::Zero());
    // Membership of every pixel, recomputed with acos.
    const Eigen::Vector3d centre = c.direction.normalized();
    for (int y = 0; y < h; y += 3) {
      for (int x = 0; x < w; x += 3) {
        const double angle = std::acos(std::clamp(p.pixel_direction(x, y).dot(centre), -1., 1.));
        if (std::abs(angle - c.radius) < 1e-6) continue;  // acos is too coarse to decide
        EXPECT_EQ(p.texel(x, y), angle < c.radius ? radiance : Rgb::Zero()) << x << " " << y;
      }
    }
  }
}

// --- Smooth functions ------------------------------------------------------------------------

TEST(Lookup, SmoothFunctionWithinInterpolationError) {
  // f(d) = d.y + 2 = cos(pi v) + 2 depends on v only. Linear interpolation between centres
  // h = 1/H apart errs by at most h^2/8 max|f_vv| = pi^2 / (8 H^2); above the first row's
  // centres (and below the last) the clamped value errs by 1 - cos(pi / (2H)), below the
  // same bound. Nearest lookup would err by ~ pi / (2H), 20 times more at H = 32.
  const int h = 32, w = 2 * h;
  const Probe p = make_from_function(
      w, h, [](const Eigen::Vector3d& d) { return Rgb::Constant(float(d.y() + 2)); });
  const double bound = kPi * kPi / (8.0 * h * h) + kFloatStorage;
  std::mt19937 rng(2);
  double worst = 0, worst_nearest = 0;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d d = random_direction(rng);
    worst = std::max(worst, std::abs(p.lookup(d).x() - (d.y() + 2)));
    worst_nearest = std::max(worst_nearest, std::abs(p.lookup_nearest(d).x() - (d.y() + 2)));
  }
  EXPECT_LE(worst, bound);
  EXPECT_GT(worst_nearest, 5 * bound);  // the test can tell bilinear from nearest
  // Exactly at the poles.
  EXPECT_NEAR(p.lookup({0, 1, 0}).x(), 3.0, bound);
  EXPECT_NEAR(p.lookup({0, -1, 0}).x(), 1.0, bound);
}

// A caller that has a direction's lat-long coordinates (the path tracer's escaping rays)
// reads the same radiance from them; coordinates that are not finite are refused by name.
TEST(Lookup, AtCoordinatesIsTheLookupOfTheDirection) {
  const Probe p = make_from_function(64, 32, [](const Eigen::Vector3d& d) {
    return Rgb(float(d.x() + 2), float(d.y() * d.z() + 1), float(d.z() + 3));
  });
  std::mt19937 rng(4);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d d = random_direction(rng);
    EXPECT_EQ(p.lookup_uv(probes::latlong_uv(d)), p.lookup(d));
  }
  EXPECT_EQ(p.lookup_uv(probes::latlong_uv({0, 1, 0})), p.lookup({0, 1, 0}));
  EXPECT_THROW(p.lookup_uv(Eigen::Vector2d(std::nan(""), 0.5)), probes::ProbeError);
  EXPECT_THROW(Probe().lookup_uv(Eigen::Vector2d(0.5, 0.5)), probes::ProbeError);
}

TEST(Lookup, SmoothFunctionOfAzimuth) {
  // f(d) = d.x + 2 d.y + 3 varies in u too, across the seam. Tensor-product linear
  // interpolation errs by at most (hu^2 max|f_uu| + hv^2 max|f_vv|) / 8 with hu = 1/W,
  // hv = 1/H, |f_uu| <= (2 pi)^2 and |f_vv| <= pi^2 (1 + 2): total pi^2 / (2 H^2) for
  // W = 2H. Only between the first and last rows' centres: beyond them the v-clamp is a
  // first-order error for d.x, which is not smooth through the pole in (u, v).
  const int h = 32, w = 2 * h;
  auto f = [](const Eigen::Vector3d& d) { return d.x() + 2 * d.y() + 3; };
  const Probe p = make_from_function(
      w, h, [&](const Eigen::Vector3d& d) { return Rgb::Constant(float(f(d))); });
  const double bound = kPi * kPi / (2.0 * h * h) + kFloatStorage;
  std::mt19937 rng(3);
  double worst = 0;
  int checked = 0;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d d = random_direction(rng);
    const double v = latlong_uv(d).y();
    if (v < 0.5 / h || v > 1 - 0.5 / h) continue;
    worst = std::max(worst, std::abs(p.lookup(d).x() - f(d)));
    ++checked;
  }
  EXPECT_GT(checked, 19000);
  EXPECT_LE(worst, bound);
}

TEST(Procedural, FunctionSamplesPixelCentres) {
  // Every texel is f at its own centre, whatever thread filled it.
  const int h = 48, w = 96;
  auto f = [](const Eigen::Vector3d& d) { return Rgb(float(d.x()), float(d.y()), float(d.z())); };
  const Probe p = make_from_function(w, h, f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) ASSERT_EQ(p.texel(x, y), f(p.pixel_direction(x, y)));
  }
}

TEST(Procedural, RejectsBadArguments) {
  EXPECT_THROW(make_constant(10, 10, Rgb::Ones()), ProbeError);
  EXPECT_THROW(make_constant(-2, -1, Rgb::Ones()), ProbeError);
  EXPECT_THROW(make_constant(0, 0, Rgb::Ones()), ProbeError);
  EXPECT_THROW(make_constant(8, 4, Rgb(1, std::numeric_limits<float>::quiet_NaN(), 1)), ProbeError);
  EXPECT_THROW(make_from_function(8, 4,
                                  [](const Eigen::Vector3d& d) {
                                    return Rgb::Constant(d.y() > 0.9 ? INFINITY : 1.0f);
                                  }),
               ProbeError);
  EXPECT_THROW(make_sun(8, 4, Eigen::Vector3d::Zero(), 0.1, Rgb::Ones()), ProbeError);
  EXPECT_THROW(make_sun(8, 4, Eigen::Vector3d::UnitY(), -0.1, Rgb::Ones()), ProbeError);
}

TEST(ProbeClass, ValidatesItsInput) {
  EXPECT_NO_THROW(Probe(4, 2, std::vector<Rgb>(8, Rgb::Ones())));
  EXPECT_NO_THROW(Probe(4, 2, std::vector<Rgb>(8, -Rgb::Ones())));  // signed is allowed
  EXPECT_THROW(Probe(4, 4, std::vector<Rgb>(16, Rgb::Ones())), ProbeError);
  EXPECT_THROW(Probe(4, 2, std::vector<Rgb>(7, Rgb::Ones())), ProbeError);
  EXPECT_THROW(Probe(0, 0, {}), ProbeError);
  std::vector<Rgb> rgb(8, Rgb::Ones());
  rgb[5].y() = std::numeric_limits<float>::infinity();
  const std::string msg = error_of([&] { Probe(4, 2, rgb, "mine"); });
  EXPECT_NE(msg.find("mine"), std::string::npos) << msg;
  EXPECT_NE(msg.find("(1, 1)"), std::string::npos) << msg;
  // Finite but past 1e20: its SH projection overflowed single precision (NaN frames).
  rgb[5].y() = 1e38f;
  const std::string huge = error_of([&] { Probe(4, 2, rgb, "bright"); });
  EXPECT_NE(huge.find("beyond the largest radiance"), std::string::npos) << huge;
  EXPECT_NO_THROW(Probe(4, 2, std::vector<Rgb>(8, Rgb::Constant(1e6f))));  // a bright sun is fine
  const Probe p = make_constant(4, 2, Rgb::Ones());
  EXPECT_THROW(p.lookup({NAN, 0, 1}), ProbeError);
  EXPECT_THROW(Probe().lookup({0, 0, 1}), ProbeError);
}

// --- Loading ---------------------------------------------------------------------------------

// w x h RGB texels drawn uniformly from [lo, hi).
std::vector<float> random_texels(int w, int h, unsigned seed, float lo, float hi) {
  std::vector<float> data(std::size_t(w) * h * 3);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(lo, hi);
  for (float& x : data) x = value(rng);
  return data;
}

TEST(Load, ExrRoundTrip) {
  const int w = 40, h = 20;
  const std::vector<float> data = random_texels(w, h, 4, 0.0f, 50000.0f);
  const fs::path path = tmp_dir() / "roundtrip.exr";
  write_image(path, w, h, 3, data);
  LoadReport report;
  const Probe p = load_probe(path, {}, &report);
  ASSERT_EQ(p.width(), w);
  ASSERT_EQ(p.height(), h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = (std::size_t(y) * w + x) * 3;
      ASSERT_EQ(p.texel(x, y), Rgb(data[i], data[i + 1], data[i + 2])) << x << " " << y;
    }
  }
  EXPECT_EQ(report.path, path.string());
  EXPECT_EQ(report.format, "openexr");
  EXPECT_EQ(report.file_width, w);
  EXPECT_EQ(report.file_height, h);
  EXPECT_EQ(report.file_channels, 3);
  EXPECT_EQ(report.layout, Layout::kLatLong);
  EXPECT_EQ(report.negative_texels_clamped, 0u);
  EXPECT_EQ(p.name(), "roundtrip");
}

TEST(Load, HdrRoundTrip) {
  // Radiance RGBE: 8-bit mantissas with a shared exponent, truncated; each channel errs by
  // less than 2^-7 of the texel's largest channel (measured ~0.4%). Tolerance 1%.
  const int w = 32, h = 16;
  const std::vector<float> data = random_texels(w, h, 5, 0.01f, 30000.0f);
  const fs::path path = tmp_dir() / "roundtrip.hdr";
  write_image(path, w, h, 3, data);
  LoadReport report;
  const Probe p = load_probe(path, {}, &report);
  EXPECT_EQ(report.format, "hdr");
  ASSERT_EQ(p.width(), w);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = (std::size_t(y) * w + x) * 3;
      const Rgb expected(data[i], data[i + 1], data[i + 2]);
      const float tol = 0.01f * expected.maxCoeff();
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(p.texel(x, y)[c], expected[c], tol) << x << " " << y;
    }
  }
}

// The Radiance reader is ours (probes/src/rgbe_file.h); OpenImageIO, reading the same
// files, is the oracle: bit-identical texels for run-length lines (width 8 and more, with
// constant stretches so that runs occur) and flat ones (width below 8).
std::vector<float> read_with_oiio(const fs::path& path, int* w, int* h) {
  auto in = OIIO::ImageInput::open(path.string());
  EXPECT_TRUE(in) << OIIO::geterror();
  if (!in) return {};
  *w = in->spec().width;
  *h = in->spec().height;
  std::vector<float> data(std::size_t(*w) * *h * 3);
  EXPECT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, data.data()));
  return data;
}

TEST(Load, HdrReaderMatchesOpenImageIOBitForBit) {
  for (const auto& [w, h] : {std::pair{64, 32}, std::pair{4, 2}, std::pair{300, 150}}) {
    std::vector<float> data = random_texels(w, h, unsigned(w), 0.0f, 2000.0f);
    for (std::size_t i = 0; i < data.size() / 3; i += 7)  // constant stretches: runs
      for (std::size_t j = i; j < std::min(data.size() / 3, i + 4); ++j)
        for (int c = 0; c < 3; ++c) data[3 * j + c] = data[3 * i + c];
    for (std::size_t i = 0; i < data.size(); i += 11) data[i] = 0.0f;  // zero exponents
    const fs::path path = tmp_dir() / ("oracle" + std::to_string(w) + ".hdr");
    write_image(path, w, h, 3, data);
    int ow = 0, oh = 0;
    const std::vector<float> oracle = read_with_oiio(path, &ow, &oh);
    const Probe p = load_probe(path);
    ASSERT_EQ(p.width(), ow);
    ASSERT_EQ(p.height(), oh);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = (std::size_t(y) * w + x) * 3;
        ASSERT_EQ(p.texel(x, y), Rgb(oracle[i], oracle[i + 1], oracle[i + 2]))
            << w << " x " << h << " at " << x << ", " << y;
      }
  }
}

namespace {

std::string radiance_header(const std::string& resolution) {
  return "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1.0\n\n" + resolution + "\n";
}

// One new-style run-length line of width 8 for R = G = B = 128, E = e (each channel one
// run of 8), i.e. every texel 128 x 2^(e - 136).
std::string rle_line(unsigned char e) {
  return std::string{2, 2, 0, 8} + std::string{char(128 + 8), char(128)} +
         std::string{char(128 + 8), char(128)} + std::string{char(128 + 8), char(128)} +
         std::string{char(128 + 8), char(e)};
}

}  // namespace

TEST(Load, HdrReaderDecodesHandWrittenLines) {
  // "+Y 4": the bottom row comes first. Rows written with E 139, 138, 137, 136 read back
  // top to bottom as 128, 256, 512, 1024.
  const fs::path flipped = tmp_dir() / "flipped.hdr";
  std::ofstream(flipped, std::ios::binary) << radiance_header("+Y 4 +X 8") << rle_line(139)
                                           << rle_line(138) << rle_line(137) << rle_line(136);
  const Probe p = load_probe(flipped, {Layout::kLatLong});
  for (int y = 0; y < 4; ++y) EXPECT_EQ(p.texel(5, y), Rgb::Constant(128.0f * float(1 << y))) << y;
  // The old scheme: a pixel, then (1, 1, 1, 3) repeats it 3 times; width 4 (flat lines).
  const fs::path old = tmp_dir() / "old_rle.hdr";
  std::string line = std::string{char(64), char(32), char(16), char(129)} + std::string{1, 1, 1, 3};
  std::ofstream(old, std::ios::binary) << radiance_header("-Y 2 +X 4") << line << line;
  const Probe q = load_probe(old, {Layout::kLatLong});
  for (int x = 0; x < 4; ++x) EXPECT_EQ(q.texel(x, 1), Rgb(0.5f, 0.25f, 0.125f)) << x;
}

TEST(LoadErrors, DamagedHdrFilesNameTheCause) {
  const auto message = [](const std::string& name, const std::string& bytes) {
    const fs::path path = tmp_dir() / name;
    std::ofstream(path, std::ios::binary) << bytes;
    return error_of([&] { load_probe(path, {Layout::kLatLong}); });
  };
  std::string m = message("xyze.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 2 +X 4\n");
  EXPECT_NE(m.find("xyze.hdr"), std::string::npos) << m;
  EXPECT_NE(m.find("32-bit_rle_xyze"), std::string::npos) << m;
  m = message("transposed.hdr", radiance_header("+X 8 -Y 4"));
  EXPECT_NE(m.find("resolution line"), std::string::npos) << m;
  m = message("overrun.hdr", radiance_header("-Y 1 +X 8") + std::string{2, 2, 0, 8} +
                                 std::string{char(128 + 9), 7});
  EXPECT_NE(m.find("past the end of the line"), std::string::npos) << m;
  m = message("cut.hdr", radiance_header("-Y 2 +X 8") + rle_line(136));
  EXPECT_NE(m.find("scanline 1 of 2"), std::string::npos) << m;
  EXPECT_NE(m.find("ends inside it"), std::string::npos) << m;
  m = message("repeat_first.hdr", radiance_header("-Y 1 +X 4") + std::string{1, 1, 1, 3});
  EXPECT_NE(m.find("before the line's first pixel"), std::string::npos) << m;
  m = message("endless.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n" + std::string(70000, 'x'));
  EXPECT_NE(m.find("runs past"), std::string::npos) << m;
}

TEST(Load, OneChannelIsGreyAndAlphaIsIgnored) {
  const int w = 16, h = 8;
  std::vector<float> grey(std::size_t(w) * h), rgba(std::size_t(w) * h * 4);
  for (std::size_t i = 0; i < grey.size(); ++i) {
    grey[i] = 0.25f * float(i);
    for (int c = 0; c < 3; ++c) rgba[4 * i + c] = float(i) + c;
    rgba[4 * i + 3] = -7.0f;  // a negative alpha must neither be used nor counted
  }
  const fs::path grey_path = tmp_dir() / "grey.exr";
  write_image(grey_path, w, h, 1, grey);
  LoadReport report;
  const Probe g = load_probe(grey_path, {}, &report);
  EXPECT_EQ(report.file_channels, 1);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) ASSERT_EQ(g.texel(x, y), Rgb::Constant(grey[y * w + x]));
  }
  const fs::path rgba_path = tmp_dir() / "rgba.exr";
  write_image(rgba_path, w, h, 4, rgba);
  const Probe c = load_probe(rgba_path, {}, &report);
  EXPECT_EQ(report.file_channels, 4);
  EXPECT_EQ(report.negative_texels_clamped, 0u);
  EXPECT_EQ(c.texel(3, 2), Rgb(35, 36, 37));
}

TEST(Load, EightBitIsDecodedFromSrgb) {
  // OpenImageIO reads an 8-bit PNG as code / 255 without decoding; the loader applies the
  // sRGB curve (IEC 61966-2-1), recomputed here.
  const int w = 4, h = 2;
  std::vector<float> data(std::size_t(w) * h * 3);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = float(i * 10) / 255.0f;
  const fs::path path = tmp_dir() / "srgb.png";
  write_image(path, w, h, 3, data, OIIO::TypeDesc::UINT8);
  const Probe p = load_probe(path);
  for (std::size_t i = 0; i < data.size(); ++i) {
    const double c = double(i * 10) / 255.0;
    const double linear = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    const int x = int(i / 3) % w, y = int(i / 3) / w;
    EXPECT_NEAR(p.texel(x, y)[int(i % 3)], linear, 1e-6) << i;
  }
}

// The angular map's orientation (probes/load.h), written independently of the loader:
// pixel (i, j) of an n x n map looks along the direction at angle pi r from -Z, where r is
// its centre's distance from the image centre in half-widths, toward image right = +X and
// image up = +Y. Outside the disc: black.
std::vector<float> angular_image(int n,
                                 const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& f) {
  std::vector<float> data(std::size_t(n) * n * 3, 0.0f);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double sx = 2.0 * (i + 0.5) / n - 1.0, sy = 1.0 - 2.0 * (j + 0.5) / n;
      const double r = std::hypot(sx, sy);
      if (r > 1.0) continue;
      const double a = kPi * r;
      const Eigen::Vector3d d(std::sin(a) * sx / r, std::sin(a) * sy / r, -std::cos(a));
      const Eigen::Vector3d c = f(d);
      for (int k = 0; k < 3; ++k) data[(std::size_t(j) * n + i) * 3 + k] = float(c[k]);
    }
  }
  return data;
}

TEST(Load, AngularMapBecomesLatLong) {
  // Radiance = direction mapped to colour. In the angular image a direction moves pi / n
  // per pixel (pi radians over the half-width n / 2), so d's second derivatives there are
  // at most ~(pi / n)^2 / sin(a) per pixel^2 (the rim is singular). Away from the rim
  // (a < 0.8 pi, sin a > 0.58) bilinear errs by at most 2 * (1/8) * 2 (pi/n)^2 / 0.58,
  // below 1 (pi/n)^2 per stage; the test's own bilinear lookup in the lat-long result adds
  // pi^2 / (2 n^2) (Lookup.SmoothFunctionOfAzimuth). Tolerance 3 (pi / n)^2. A mirrored or
  // rotated mapping errs by ~1 or more.
  const int n = 128;
  auto f = [](const Eigen::Vector3d& d) { return Eigen::Vector3d(d + Eigen::Vector3d::Ones()); };
  const fs::path path = tmp_dir() / "angular.exr";
  write_image(path, n, n, 3, angular_image(n, f));
  LoadReport report;
  const Probe p = load_probe(path, {}, &report);
  EXPECT_EQ(report.layout, Layout::kAngular);
  EXPECT_EQ(report.file_width, n);
  ASSERT_EQ(p.width(), 2 * n);
  ASSERT_EQ(p.height(), n);
  const double tol = 3 * (kPi / n) * (kPi / n);
  auto near_rim = [](const Eigen::Vector3d& d) {
    return std::atan2(std::hypot(d.x(), d.y()), -d.z()) > 0.8 * kPi;
  };
  // At the lat-long pixel centres (one resampling stage).
  double worst_texel = 0;
  for (int y = 0; y < p.height(); ++y) {
    for (int x = 0; x < p.width(); ++x) {
      const Eigen::Vector3d d = p.pixel_direction(x, y);
      if (near_rim(d)) continue;
      worst_texel =
          std::max(worst_texel, (p.texel(x, y).cast<double>() - f(d)).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_LE(worst_texel, tol);
  // Through lookups at random directions (away from the rim and from the lat-long poles).
  std::mt19937 rng(6);
  double worst = 0;
  for (int i = 0; i < 5000; ++i) {
    const Eigen::Vector3d d = random_direction(rng);
    const double v = latlong_uv(d).y();
    if (near_rim(d) || v < 0.5 / n || v > 1 - 0.5 / n) continue;
    worst = std::max(worst, (p.lookup(d).cast<double>() - f(d)).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(worst, tol);
  // The named directions, exactly: the centre of the disc is -Z (colour (1, 1, 0)).
  EXPECT_TRUE(p.lookup({0, 0, -1}).isApprox(Rgb(1, 1, 0), 1e-2f)) << p.lookup({0, 0, -1});
  EXPECT_TRUE(p.lookup({1, 0, 0}).isApprox(Rgb(2, 1, 1), 1e-2f)) << p.lookup({1, 0, 0});
  EXPECT_TRUE(p.lookup({0, 1, 0}).isApprox(Rgb(1, 2, 1), 1e-2f)) << p.lookup({0, 1, 0});
}

TEST(Load, ForcedLayoutWhenItAgrees) {
  const fs::path path = tmp_dir() / "forced.exr";
  write_image(path, 8, 4, 3, std::vector<float>(8 * 4 * 3, 1.0f));
  LoadReport report;
  EXPECT_NO_THROW(load_probe(path, {Layout::kLatLong}, &report));
  EXPECT_EQ(report.layout, Layout::kLatLong);
}

TEST(Load, NegativeTexelsAreClampedAndCounted) {
  const int w = 8, h = 4;
  std::vector<float> data(std::size_t(w) * h * 3, 1.0f);
  data[(1 * w + 2) * 3 + 0] = -0.5f;
  data[(1 * w + 2) * 3 + 2] = -0.25f;  // same texel: counted once
  data[(3 * w + 7) * 3 + 1] = -1e-3f;
  const fs::path path = tmp_dir() / "negative.exr";
  write_image(path, w, h, 3, data);
  LoadReport report;
  const Probe p = load_probe(path, {}, &report);
  EXPECT_EQ(report.negative_texels_clamped, 2u);
  EXPECT_EQ(p.texel(2, 1), Rgb(0, 1, 0));
  EXPECT_EQ(p.texel(7, 3), Rgb(1, 0, 1));
  EXPECT_EQ(p.texel(0, 0), Rgb(1, 1, 1));
}

TEST(Load, LayoutNames) {
  EXPECT_STREQ(layout_name(Layout::kAuto), "auto");
  EXPECT_STREQ(layout_name(Layout::kLatLong), "lat-long");
  EXPECT_STREQ(layout_name(Layout::kAngular), "angular");
}

// --- Load errors: each a ProbeError naming the file ------------------------------------------

void expect_error(const fs::path& path, const LoadOptions& options,
                  const std::vector<std::string>& fragments) {
  const std::string msg = error_of([&] { load_probe(path, options); });
  EXPECT_NE(msg.find(path.string()), std::string::npos) << msg;
  for (const std::string& f : fragments) EXPECT_NE(msg.find(f), std::string::npos) << msg;
}

TEST(LoadErrors, MissingFile) {
  expect_error(tmp_dir() / "no_such_probe.exr", {}, {"no such file"});
}

TEST(LoadErrors, FolderWithoutCubeFaces) {
  // A folder is read as a six-face cube map (probes/load.h); without the faces it is named.
  const fs::path dir = tmp_dir() / "no_faces";
  fs::create_directories(dir);
  expect_error(dir, {}, {"folder", "px"});
}

TEST(LoadErrors, GarbageBytes) {
  const fs::path path = tmp_dir() / "garbage.exr";
  {
    std::ofstream out(path, std::ios::binary);
    for (int i = 0; i < 1000; ++i) out.put(char(i * 37 + 11));
  }
  // OpenImageIO's own words follow the path.
  expect_error(path, {}, {"not an OpenEXR file"});
}

TEST(LoadErrors, TruncatedExr) {
  const fs::path good = tmp_dir() / "to_truncate.exr";
  write_image(good, 64, 32, 3, std::vector<float>(64 * 32 * 3, 1.0f));
  const auto size = fs::file_size(good);
  const fs::path path = tmp_dir() / "truncated.exr";
  fs::copy_file(good, path, fs::copy_options::overwrite_existing);
  fs::resize_file(path, size / 2);
  expect_error(path, {}, {});
}

TEST(LoadErrors, WrongAspect) {
  const fs::path path = tmp_dir() / "three_to_one.exr";
  write_image(path, 30, 10, 3, std::vector<float>(30 * 10 * 3, 1.0f));
  expect_error(path, {}, {"30x10", "neither a 2:1 lat-long map, a square angular map nor a 4:3"});
}

TEST(LoadErrors, ForcedLayoutDisagrees) {
  const fs::path latlong = tmp_dir() / "forced_latlong.exr";
  write_image(latlong, 16, 8, 3, std::vector<float>(16 * 8 * 3, 1.0f));
  expect_error(latlong, {Layout::kAngular}, {"16x8", "angular"});
  const fs::path square = tmp_dir() / "forced_square.exr";
  write_image(square, 8, 8, 3, std::vector<float>(8 * 8 * 3, 1.0f));
  expect_error(square, {Layout::kLatLong}, {"8x8", "lat-long"});
}

TEST(LoadErrors, TwoChannels) {
  const fs::path path = tmp_dir() / "two_channels.exr";
  write_image(path, 8, 4, 2, std::vector<float>(8 * 4 * 2, 1.0f));
  expect_error(path, {}, {"2 channels"});
}

TEST(LoadErrors, DataWindowSmallerThanDisplayWindow) {
  const fs::path path = tmp_dir() / "cropped.exr";
  auto out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out);
  OIIO::ImageSpec spec(16, 8, 3, OIIO::TypeDesc::FLOAT);
  spec.x = 4;
  spec.full_width = 32;
  spec.full_height = 16;
  ASSERT_TRUE(out->open(path.string(), spec)) << out->geterror();
  const std::vector<float> data(16 * 8 * 3, 1.0f);
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, data.data())) << out->geterror();
  ASSERT_TRUE(out->close());
  expect_error(path, {}, {"display window"});
}

TEST(LoadErrors, NaNTexel) {
  const int w = 16, h = 8;
  std::vector<float> data(std::size_t(w) * h * 3, 1.0f);
  data[(2 * w + 3) * 3 + 1] = std::numeric_limits<float>::quiet_NaN();
  const fs::path path = tmp_dir() / "nan.exr";
  write_image(path, w, h, 3, data);
  expect_error(path, {}, {"1 texel is NaN or Inf", "(3, 2)"});
}

TEST(LoadErrors, InfTexels) {
  const int w = 16, h = 8;
  std::vector<float> data(std::size_t(w) * h * 3, 1.0f);
  data[(5 * w + 9) * 3 + 0] = std::numeric_limits<float>::infinity();
  data[(6 * w + 1) * 3 + 2] = std::numeric_limits<float>::infinity();
  data[(6 * w + 2) * 3 + 2] = -std::numeric_limits<float>::infinity();
  const fs::path path = tmp_dir() / "inf.exr";
  write_image(path, w, h, 3, data);
  expect_error(path, {}, {"3 texels are NaN or Inf", "(9, 5)"});
}

// --- Real probes -----------------------------------------------------------------------------

const fs::path kStudioLights = "/usr/share/blender/datafiles/studiolights/world";

void check_real_probe(const fs::path& path) {
  SCOPED_TRACE(path.string());
  LoadReport report;
  const Probe p = load_probe(path, {}, &report);
  EXPECT_EQ(p.width(), 1024);
  EXPECT_EQ(p.height(), 512);
  EXPECT_EQ(report.layout, Layout::kLatLong);
  EXPECT_EQ(report.format, "openexr");
  // Blender's probes are DWAB-compressed (lossy) and decode with a few tiny negative texels
  // (down to about -0.004), which the loader clamps: a handful, never a large part.
  EXPECT_LT(report.negative_texels_clamped, p.texels().size() / 100);
  // The oracle is the file read directly with OpenImageIO: every texel is the file's, clamped
  // at zero (bit-exact), the clamp count is the file's negatives, and the mean is the
  // solid-angle sum over rows (cos theta_top - cos theta_bottom) 2 pi / W, over 4 pi.
  auto in = OIIO::ImageInput::open(path.string());
  ASSERT_TRUE(in) << OIIO::geterror();
  const int w = in->spec().width, h = in->spec().height, channels = in->spec().nchannels;
  ASSERT_GE(channels, 3);
  std::vector<float> file(std::size_t(w) * h * channels);
  ASSERT_TRUE(in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, file.data()));
  ASSERT_EQ(std::size_t(w) * h, p.texels().size());
  std::uint64_t negatives = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int y = 0; y < h; ++y) {
    const double solid_angle =
        2 * std::numbers::pi / w *
        (std::cos(std::numbers::pi * y / h) - std::cos(std::numbers::pi * (y + 1) / h));
    for (int x = 0; x < w; ++x) {
      const float* f = file.data() + (std::size_t(y) * w + x) * channels;
      bool negative = false;
      for (int c = 0; c < 3; ++c) {
        negative |= f[c] < 0.0f;
        const float expected = std::max(f[c], 0.0f);
        ASSERT_EQ(p.texel(x, y)[c], expected) << "texel (" << x << ", " << y << ")";
        sum[c] += solid_angle * expected;
      }
      negatives += negative;
    }
  }
  EXPECT_EQ(report.negative_texels_clamped, negatives);
  const Eigen::Vector3d expected_mean = sum / (4 * std::numbers::pi);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(p.mean_radiance()[c], expected_mean[c], 1e-5 * expected_mean[c]) << "channel " << c;
  const Rgb m = p.max_texel(), mean = p.mean_radiance();
  std::printf("  %-10s max (%g, %g, %g)  mean (%g, %g, %g)\n", path.stem().c_str(), m.x(), m.y(),
              m.z(), mean.x(), mean.y(), mean.z());
}

TEST(RealProbes, Forest) {
  const fs::path path = kStudioLights / "forest.exr";
  if (!fs::exists(path)) GTEST_SKIP() << path << " is absent (Debian package blender-data)";
  check_real_probe(path);
  const Probe p = load_probe(path);
  EXPECT_GT(p.max_texel().maxCoeff(), 1000.0f);  // a sun-like peak
  // The mean is the solid-angle weighted average: between the smallest texel and the max.
  EXPECT_LT(p.mean_radiance().maxCoeff(), p.max_texel().maxCoeff());
}

TEST(RealProbes, AllStudioLights) {
  if (!fs::is_directory(kStudioLights)) GTEST_SKIP() << kStudioLights << " is absent";
  int count = 0;
  for (const auto& entry : fs::directory_iterator(kStudioLights)) {
    if (entry.path().extension() != ".exr") continue;
    check_real_probe(entry.path());
    ++count;
  }
  EXPECT_GT(count, 0);
}

}  // namespace
}  // namespace probes
