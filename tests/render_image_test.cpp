// Image output and the camera: the EXR holds exactly the framebuffer (read back through
// OpenImageIO itself, not our reader), the PNG holds the documented tone map, writes are
// atomic, and the default camera frames the bounding sphere.
#include "render/camera.h"
#include "render/image.h"
#include "render/image_difference.h"
#include "render/renderer.h"

#include "meshes/procedural.h"
#include "probes/procedural.h"
#include "render/gl_context.h"
#include "test_support.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <vector>

namespace {

namespace fs = std::filesystem;

// A diffuse, one-cluster set with no PCs: radiance = mean . l for every vertex, enough to
// fill a framebuffer with a real render.
cpca::CompressedSet constant_set(std::size_t vertices, int order) {
  cpca::CompressedSet s;
  s.order = order;
  s.channels = 1;
  s.columns = 1;
  s.vertex_count = vertices;
  s.cluster_count = 1;
  s.component_count = 0;
  s.cluster_of.assign(vertices, 0);
  s.means.assign(std::size_t(order * order), 0.f);
  s.means[0] = 1.f;
  return s;
}

render::Image rendered_image(render::GlContext&) {
  const meshes::Mesh mesh = meshes::make_sphere(1.f, 16, 8);
  const cpca::CompressedSet set = constant_set(mesh.vertex_count(), 2);
  const probes::Probe probe = probes::make_from_function(32, 16, [](const Eigen::Vector3d& d) {
    return probes::Rgb(float(1.0 + d.x()), float(1.0 + d.y()), float(2.0 + d.z()));
  });
  prt::ShLighting l = prt::ShLighting::Zero(4, 3);
  l.row(0) << 0.5, 1.5, 3.0;
  render::RendererOptions o;
  o.mode = render::Mode::kSinglepass;
  render::Renderer r(mesh, &set, nullptr, &probe, o);
  r.render(render::frame_sphere(Eigen::Vector3d::Zero(), 1.0, 40, 30), l,
           Eigen::Matrix3d::Identity());
  return r.read_image();
}

TEST(Image, ExrRoundTripThroughOpenImageIo) {
  render::GlContext ctx;
  const render::Image image = rendered_image(ctx);
  ASSERT_EQ(image.width, 40);
  ASSERT_EQ(image.height, 30);
  const fs::path path = test_support::scratch("render_image", "round_trip.exr");
  render::write_exr(path, image);

  auto in = OIIO::ImageInput::open(path.string());
  ASSERT_TRUE(in) << OIIO::geterror();
  const OIIO::ImageSpec& spec = in->spec();
  EXPECT_EQ(spec.width, 40);
  EXPECT_EQ(spec.height, 30);
  ASSERT_EQ(spec.nchannels, 4);
  EXPECT_EQ(spec.channelnames, (std::vector<std::string>{"R", "G", "B", "A"}));
  EXPECT_EQ(spec.alpha_channel, 3);
  std::vector<float> pixels(std::size_t(40) * 30 * 4);
  ASSERT_TRUE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, pixels.data()));
  EXPECT_EQ(pixels, image.rgba);  // float EXR: bit exact
  // The render has both coverage values and radiance (mesh: 1, 1.5 .. on the background).
  int covered = 0;
  for (std::size_t i = 3; i < pixels.size(); i += 4) covered += pixels[i] == 1.f;
  EXPECT_GT(covered, 50);
  EXPECT_LT(covered, 40 * 30);
  // The centre pixel is the sphere: radiance (0.5, 1.5, 3) times the constant y_0 = 1
  // (diffuse: the mean . l with mean = e_0).
  const float* centre = image.pixel(20, 15);
  EXPECT_FLOAT_EQ(centre[0], 0.5f);
  EXPECT_FLOAT_EQ(centre[2], 3.0f);
  EXPECT_EQ(centre[3], 1.f);
}

TEST(Image, PngHoldsTheToneMappedValues) {
  render::GlContext ctx;
  const render::Image image = rendered_image(ctx);
  const fs::path path = test_support::scratch("render_image", "tone.png");
  render::write_png(path, image, 1.0);
  const render::Image png = render::read_image(path);
  ASSERT_EQ(png.width, image.width);
  ASSERT_EQ(png.height, image.height);
  for (int y = 0; y < image.height; y += 7)
    for (int x = 0; x < image.width; x += 5)
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(png.pixel(x, y)[c], render::tone_map(image.pixel(x, y)[c], 1.0),
                    0.5 / 255.0 + 1e-6);
}

TEST(Image, ToneMapIsMonotoneAndBounded) {
  EXPECT_EQ(render::tone_map(0.f, 0.0), 0.f);
  EXPECT_EQ(render::tone_map(-1.f, 0.0), 0.f);
  float previous = 0.f;
  for (float v = 0.01f; v < 100.f; v *= 1.5f) {
    const float t = render::tone_map(v, 0.0);
    // The ACES fit reaches 1 (then clamps) a little above 10.
    if (v < 8.f) {
      EXPECT_GT(t, previous) << v;
    }
    EXPECT_GE(t, previous);
    EXPECT_LE(t, 1.f);
    previous = t;
  }
  // One stop of exposure doubles the input.
  EXPECT_FLOAT_EQ(render::tone_map(0.25f, 1.0), render::tone_map(0.5f, 0.0));
}

TEST(Image, WritesAreAtomic) {
  render::Image image;
  image.width = 4;
  image.height = 2;
  image.rgba.assign(32, 0.5f);
  const fs::path dir = test_support::scratch("render_image", "atomic");
  fs::remove_all(dir);
  fs::create_directories(dir);
  render::write_exr(dir / "a.exr", image);
  render::write_png(dir / "a.png", image);
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"a.exr", "a.png"}));  // no temporaries left
  EXPECT_THROW(render::write_exr(dir / "missing" / "b.exr", image), render::ImageError);
  EXPECT_THROW(render::write_exr(dir / "c.unknownext", image), render::ImageError);
  names.clear();
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  EXPECT_EQ(names.size(), 2u);
}

TEST(Camera, FramesTheBoundingSphere) {
  const Eigen::Vector3d centre(1, 2, 3);
  for (auto [w, h] : {std::pair{64, 48}, {48, 64}}) {
    const render::Camera c = render::frame_sphere(centre, 2.0, w, h, 40.0);
    EXPECT_NO_THROW(c.validate());
    const Eigen::Matrix4d clip = c.clip_from_world();
    // Every point of the sphere projects inside the image and between the clip planes.
    double extent = 0.0;
    for (int i = 0; i < 500; ++i) {
      const double z = -1.0 + 2.0 * (i + 0.5) / 500, phi = 2.399963 * i;
      const Eigen::Vector3d p =
          centre + 2.0 * Eigen::Vector3d(std::sqrt(1 - z * z) * std::cos(phi),
                                         std::sqrt(1 - z * z) * std::sin(phi), z);
      const Eigen::Vector4d q = clip * p.homogeneous();
      const Eigen::Vector3d ndc = q.head<3>() / q.w();
      EXPECT_LT(ndc.head<2>().cwiseAbs().maxCoeff(), 1.0);
      EXPECT_LT(std::abs(ndc.z()), 1.0);
      extent = std::max(extent, ndc.head<2>().cwiseAbs().maxCoeff());
    }
    EXPECT_GT(extent, 0.8);  // framed, not lost in the middle
  }
}

TEST(Camera, PixelDirectionsMatchTheProjection) {
  render::Camera c = render::frame_sphere(Eigen::Vector3d::Zero(), 1.0, 32, 24, 50.0);
  c.eye = Eigen::Vector3d(2, 1, 3);
  const Eigen::Matrix4d clip = c.clip_from_world();
  for (auto [x, y] : {std::pair{0, 0}, {31, 0}, {10, 20}}) {
    const Eigen::Vector3d p = c.eye + 2.0 * c.pixel_direction(x, y);
    const Eigen::Vector4d q = clip * p.homogeneous();
    EXPECT_NEAR((q.x() / q.w() + 1) * 0.5 * 32, x + 0.5, 1e-9);
    EXPECT_NEAR((1 - q.y() / q.w()) * 0.5 * 24, y + 0.5, 1e-9);  // row 0 at the top
  }
  c.up = c.target - c.eye;
  EXPECT_THROW(c.validate(), std::invalid_argument);
}

}  // namespace

namespace {

render::Image flat_image(int w, int h, float value, float alpha) {
  render::Image image;
  image.width = w;
  image.height = h;
  image.rgba.assign(std::size_t(w) * h * 4, value);
  for (std::size_t i = 3; i < image.rgba.size(); i += 4) image.rgba[i] = alpha;
  return image;
}

}  // namespace

// Worked by hand: over the covered pixels the error is 0.5 on one pixel's three channels and
// 0 elsewhere, the reference 2 everywhere; uncovered pixels, whatever they hold, do not count.
TEST(ImageDifference, CountsOnlyPixelsBothCoverAndMatchesAHandComputation) {
  render::Image reference = flat_image(4, 2, 2.f, 1.f);
  render::Image image = reference;
  for (int c = 0; c < 3; ++c) image.pixel(1, 0)[c] = 2.5f;
  for (int c = 0; c < 3; ++c) image.pixel(3, 1)[c] = 100.f;  // not covered in the reference
  reference.pixel(3, 1)[3] = 0.f;
  const render::ImageDifference d = render::image_difference(image, reference);
  EXPECT_EQ(d.pixels, 7u);
  const double rmse = std::sqrt(3 * 0.25 / 21.0);
  EXPECT_NEAR(d.rmse, rmse, 1e-12);
  EXPECT_NEAR(d.relative_rmse, rmse / 2.0, 1e-12);
  EXPECT_NEAR(d.mean_abs, 1.5 / 21.0, 1e-12);
  EXPECT_NEAR(d.max_abs, 0.5, 1e-12);
  // Coverage 0 counts every pixel, the uncovered one's 98 included.
  EXPECT_NEAR(render::image_difference(image, reference, 0.f).max_abs, 98.0, 1e-9);
}

// Against a known exact image T: references A and B are T plus independent noise of 5 %, the
// image is T scaled by 1.03 (3 % off T, in relative RMSE). Against A alone it measures about
// sqrt(3^2 + 5^2) %; with B the noise comes out and the exact figure returns.
TEST(ImageDifference, SecondReferenceTakesTheReferenceNoiseOut) {
  const int w = 400, h = 300;
  render::Image exact = flat_image(w, h, 0.f, 1.f);
  std::mt19937 rng(11);
  std::normal_distribution<float> gauss(0.f, 1.f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        exact.pixel(x, y)[c] = 1.f + 0.5f * std::sin(0.05f * float(x + c * y));
  double exact_squared = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        exact_squared += double(exact.pixel(x, y)[c]) * exact.pixel(x, y)[c];
  const float sigma = 0.05f * float(std::sqrt(exact_squared / (3.0 * w * h)));
  render::Image a = exact, b = exact, image = exact;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        a.pixel(x, y)[c] += sigma * gauss(rng);
        b.pixel(x, y)[c] += sigma * gauss(rng);
        image.pixel(x, y)[c] *= 1.03f;
      }
  const render::ImageDifference alone = render::image_difference(image, a);
  EXPECT_EQ(alone.reference_noise, -1.0);
  EXPECT_EQ(alone.corrected_relative_rmse, -1.0);
  EXPECT_NEAR(alone.relative_rmse, std::sqrt(0.03 * 0.03 + 0.05 * 0.05), 0.002);
  const render::ImageDifference d = render::image_difference(image, a, 0.999f, 0, &b);
  EXPECT_EQ(d.relative_rmse, alone.relative_rmse);
  EXPECT_NEAR(d.reference_noise, 0.05, 0.001);
  EXPECT_NEAR(d.corrected_relative_rmse, 0.03, 0.001);
  // The exact image itself, against the noisy references: its error is the noise, taken out.
  EXPECT_NEAR(render::image_difference(exact, a, 0.999f, 0, &b).corrected_relative_rmse, 0.0,
              0.005);
  // A pixel the second reference leaves uncovered is compared in none; a size mismatch or
  // a non-finite value in the second reference is refused.
  render::Image hole = b;
  hole.pixel(0, 0)[3] = 0.f;
  EXPECT_EQ(render::image_difference(image, a, 0.999f, 0, &hole).pixels, alone.pixels - 1);
  const render::Image small = flat_image(4, 2, 1.f, 1.f);
  EXPECT_THROW(render::image_difference(image, a, 0.999f, 0, &small), std::invalid_argument);
  hole.pixel(5, 5)[2] = std::nanf("");
  EXPECT_THROW(render::image_difference(image, a, 0.999f, 0, &hole), std::invalid_argument);
}

TEST(ImageDifference, RefusesDifferentSizesNoCoverageAndNonFiniteValues) {
  const render::Image a = flat_image(4, 2, 1.f, 1.f);
  EXPECT_THROW(render::image_difference(a, flat_image(2, 4, 1.f, 1.f)), std::invalid_argument);
  EXPECT_THROW(render::image_difference(a, flat_image(4, 2, 1.f, 0.f)), std::invalid_argument);
  render::Image nan = a;
  nan.pixel(0, 0)[1] = std::nanf("");
  EXPECT_THROW(render::image_difference(nan, a), std::invalid_argument);
}

// Erosion against a brute-force count: a pixel stays when every pixel of its (2 r + 1)^2
// square lies inside the image and is covered in both, on random coverage masks.
TEST(ImageDifference, ErodeKeepsExactlyThePixelsWhoseSquareIsCovered) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  for (int trial = 0; trial < 20; ++trial) {
    const int w = 5 + trial % 7, h = 4 + trial % 5, r = 1 + trial % 3;
    render::Image reference = flat_image(w, h, 1.f, 1.f), image = reference;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (unit(rng) < 0.08f) reference.pixel(x, y)[3] = 0.f;
        if (unit(rng) < 0.08f) image.pixel(x, y)[3] = 0.f;
        image.pixel(x, y)[0] = 1.f + float(x + w * y);  // each pixel's own error
      }
    std::uint64_t count = 0;
    double max_abs = 0.0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        bool inside = true;
        for (int dy = -r; dy <= r; ++dy)
          for (int dx = -r; dx <= r; ++dx) {
            const int u = x + dx, v = y + dy;
            inside = inside && u >= 0 && v >= 0 && u < w && v < h && image.pixel(u, v)[3] > 0.5f &&
                     reference.pixel(u, v)[3] > 0.5f;
          }
        if (inside) {
          ++count;
          max_abs = std::max(max_abs, double(x + w * y));
        }
      }
    if (count == 0) {
      EXPECT_THROW(render::image_difference(image, reference, 0.999f, r), std::invalid_argument);
      continue;
    }
    const render::ImageDifference d = render::image_difference(image, reference, 0.999f, r);
    EXPECT_EQ(d.pixels, count) << "trial " << trial;
    EXPECT_NEAR(d.max_abs, max_abs, 1e-9) << "trial " << trial;
  }
  EXPECT_THROW(
      render::image_difference(flat_image(4, 4, 1.f, 1.f), flat_image(4, 4, 1.f, 1.f), 0.999f, -1),
      std::invalid_argument);
}
