// Cube-map probes: texel geometry against the documented OpenGL table and brute-force
// integration, the cross and face-set readers, and the SH projection with exact texel solid
// angles against analytic values and against the lat-long projection.
#include "probes/cube_map.h"
#include "probes/load.h"
#include "probes/procedural.h"
#include "prt/cube_projection.h"
#include "prt/projection.h"
#include "prt/sh.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using probes::CrossKind;
using probes::CubeMap;
using probes::Rgb;
constexpr double kPi = std::numbers::pi;

fs::path tmp_dir(const std::string& name) {
  const fs::path dir = fs::path(PRTR_TEST_TMPDIR) / "cube_map" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void write_rgb(const fs::path& path, int w, int h, const std::vector<Rgb>& rgb) {
  auto out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out) << OIIO::geterror();
  OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::FLOAT);
  ASSERT_TRUE(out->open(path.string(), spec)) << out->geterror();
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, rgb.data())) << out->geterror();
  ASSERT_TRUE(out->close());
}

CubeMap constant_cube(int size, const Rgb& value) {
  std::array<std::vector<Rgb>, probes::kCubeFaces> faces;
  for (auto& face : faces) face.assign(std::size_t(size) * std::size_t(size), value);
  return CubeMap(size, std::move(faces));
}

CubeMap one_bright_texel(int size, int face, int x, int y) {
  std::array<std::vector<Rgb>, probes::kCubeFaces> faces;
  for (auto& f : faces) f.assign(std::size_t(size) * std::size_t(size), Rgb::Zero());
  faces[std::size_t(face)][std::size_t(y) * std::size_t(size) + std::size_t(x)] =
      Rgb(100.f, 50.f, 25.f);
  return CubeMap(size, std::move(faces));
}

TEST(CubeGeometry, FaceCentresAndEdgesFollowTheOpenGlTable) {
  const CubeMap cube = constant_cube(2, Rgb::Ones());
  const Eigen::Vector3d axes[6] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                   {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  for (int f = 0; f < 6; ++f) {
    EXPECT_TRUE(CubeMap::face_direction(f, 0, 0).isApprox(axes[f])) << probes::cube_face_name(f);
  }
  // Side faces: image up is +Y. pz: image right is +X; px: image right is -Z.
  EXPECT_GT(cube.texel_direction(0, 0, 0).y(), 0.0);
  EXPECT_GT(cube.texel_direction(4, 1, 0).x(), 0.0);
  EXPECT_LT(cube.texel_direction(0, 1, 0).z(), 0.0);
  // py: the bottom row borders pz (+Z); ny: the top row borders pz.
  EXPECT_GT(cube.texel_direction(2, 0, 1).z(), 0.0);
  EXPECT_GT(cube.texel_direction(3, 0, 0).z(), 0.0);
}

TEST(CubeGeometry, TexelSolidAnglesSumToFourPiAndMatchIntegration) {
  for (int size : {1, 3, 16, 64}) {
    const CubeMap cube = constant_cube(size, Rgb::Ones());
    double sum = 0;
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) sum += 6 * cube.texel_solid_angle(x, y);
    }
    EXPECT_NEAR(sum, 4 * kPi, 1e-12) << size;
  }
  // One off-centre texel of an 8 x 8 face against a midpoint-rule integral of the area
  // element (1 + a^2 + b^2)^(-3/2) da db over it.
  const CubeMap cube = constant_cube(8, Rgb::Ones());
  const int tx = 6, ty = 1, steps = 400;
  double integral = 0;
  const double a0 = 2.0 * tx / 8 - 1, b0 = 2.0 * ty / 8 - 1, h = 0.25 / steps;
  for (int i = 0; i < steps; ++i) {
    for (int j = 0; j < steps; ++j) {
      const double a = a0 + (i + 0.5) * h, b = b0 + (j + 0.5) * h;
      integral += std::pow(1 + a * a + b * b, -1.5) * h * h;
    }
  }
  EXPECT_NEAR(cube.texel_solid_angle(tx, ty), integral, 1e-8);
}

TEST(CubeProjection, ConstantGivesTheConstantsSh) {
  // Exact: the solid angles sum to 4 pi, and the cube's texel grid is symmetric under the
  // cube's rotations and the antipodal map, which leave no invariant in bands 1 to 3 (band 4
  // has one, so it is not tested to rounding).
  const Rgb c(0.5f, 1.0f, 2.0f);
  const prt::ShLighting sh = prt::project_cube(constant_cube(16, c), 4);
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_NEAR(sh(0, ch), c[ch] * std::sqrt(4 * kPi), 1e-12);
    for (int i = 1; i < sh.rows(); ++i) EXPECT_NEAR(sh(i, ch), 0.0, 1e-12) << i;
  }
}

TEST(CubeProjection, BrightTexelProjectsAsAPointLightInItsDirection) {
  // A single texel of radiance L and solid angle w projects to L w Y_lm(d) exactly.
  const CubeMap cube = one_bright_texel(8, 3, 2, 5);
  const prt::ShLighting sh = prt::project_cube(cube, 3);
  Eigen::VectorXd basis(9);
  prt::sh_eval(3, cube.texel_direction(3, 2, 5), basis.data());
  const double w = cube.texel_solid_angle(2, 5);
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(sh(i, 0), 100.0 * w * basis[i], 1e-12) << i;
}

// Each cross kind, written to an EXR and read back through load_probe: the bright texel is in
// the face and place it was put, and the lat-long map shows it in its direction.
TEST(CubeCross, BrightTexelLandsOnItsDirection) {
  const fs::path dir = tmp_dir("cross");
  for (CrossKind kind : {CrossKind::kHorizontal, CrossKind::kVertical}) {
    for (int face = 0; face < 6; ++face) {
      const CubeMap cube = one_bright_texel(8, face, 1, 6);
      int w = 0, h = 0;
      const std::vector<Rgb> cross = probes::cube_to_cross(cube, kind, &w, &h);
      const fs::path path = dir / ("cross_" + std::to_string(face) + ".exr");
      write_rgb(path, w, h, cross);
      probes::LoadReport report;
      const probes::Probe latlong = probes::load_probe(path, {}, &report);
      ASSERT_TRUE(report.cube);
      EXPECT_EQ(report.layout, probes::Layout::kCross);
      EXPECT_EQ(report.cross, kind);
      EXPECT_EQ(report.cube->texel(face, 1, 6), Rgb(100.f, 50.f, 25.f)) << face;
      EXPECT_EQ(latlong.width(), 32);
      // The brightest lat-long texel lies within a lat-long texel's diagonal of the direction.
      int bx = 0, by = 0;
      for (int y = 0; y < latlong.height(); ++y) {
        for (int x = 0; x < latlong.width(); ++x) {
          if (latlong.texel(x, y).x() > latlong.texel(bx, by).x()) bx = x, by = y;
        }
      }
      const double angle = std::acos(std::clamp(
          latlong.pixel_direction(bx, by).dot(cube.texel_direction(face, 1, 6)), -1.0, 1.0));
      EXPECT_LT(angle, std::sqrt(2.0) * kPi / latlong.height()) << face;
    }
  }
}

// A smooth lat-long map resampled to a cube (bilinear, face size 64) and written as a cross.
// The cube's exact projection and the lat-long map's own agree within the resampling error:
// bilinear interpolation of a smooth map errs by about h^2/8 times its second derivative,
// with h the lat-long texel (2 pi / 512 here), i.e. ~1e-4 of the map's ~1 curvature, and
// averaging over the sphere shrinks it further (measured: 6e-5 for the cube, 2e-4 for the
// cube resampled back to lat-long, against a DC term of 3.5). 5e-4 leaves a margin; a face
// in the wrong place or orientation gives errors of order 0.1 to 1 in bands 1 and 2.
TEST(CubeCross, LatLongResampledToACrossHasTheSameSh) {
  const auto radiance = [](const Eigen::Vector3d& d) {
    const double v = 1.0 + 0.6 * d.x() - 0.3 * d.y() + 0.4 * d.z() + 0.5 * d.x() * d.y() +
                     0.3 * std::exp(2.0 * (d.z() - 1.0));
    return Rgb(float(v), float(0.5 * v), float(2.0 - 0.5 * v));
  };
  const probes::Probe latlong = probes::make_from_function(512, 256, radiance);
  const CubeMap cube = probes::latlong_to_cube(latlong, 64);
  const fs::path dir = tmp_dir("resampled");
  for (CrossKind kind : {CrossKind::kHorizontal, CrossKind::kVertical}) {
    int w = 0, h = 0;
    const std::vector<Rgb> cross = probes::cube_to_cross(cube, kind, &w, &h);
    write_rgb(dir / "cross.exr", w, h, cross);
    probes::LoadReport report;
    const probes::Probe back = probes::load_probe(dir / "cross.exr", {}, &report);
    ASSERT_TRUE(report.cube);
    const prt::ShLighting exact = prt::project_cube(*report.cube, 3);
    const prt::ShLighting reference = prt::project(latlong, 3);
    EXPECT_LT((exact - reference).cwiseAbs().maxCoeff(), 5e-4) << exact - reference;
    // The lat-long map the renderer gets back projects the same way, and every command
    // (prt::project) integrates the cube the probe came from.
    EXPECT_LT((prt::project_latlong(back, 3) - reference).cwiseAbs().maxCoeff(), 5e-4);
    ASSERT_EQ(back.source_cube(), report.cube.get());
    EXPECT_EQ(prt::project(back, 3), exact);
  }
}

TEST(CubeFaces, FolderAndPatternReadTheSameCubeAsTheCross) {
  const fs::path dir = tmp_dir("faces");
  std::array<std::vector<Rgb>, probes::kCubeFaces> faces;
  for (int f = 0; f < 6; ++f) {
    for (int i = 0; i < 16; ++i) faces[std::size_t(f)].push_back(Rgb(float(f), float(i), 1.f));
  }
  const CubeMap cube(4, faces);
  for (int f = 0; f < 6; ++f) {
    write_rgb(dir / (std::string(probes::cube_face_name(f)) + ".exr"), 4, 4, faces[std::size_t(f)]);
    write_rgb(dir / (std::string("sky_") + probes::cube_face_name(f) + ".hdr"), 4, 4,
              faces[std::size_t(f)]);
  }
  // The folder holds px.exr ... and sky_px.hdr ...: the folder form takes the exact names.
  for (const fs::path& set : {dir, dir / "sky_{face}.hdr"}) {
    probes::LoadReport report;
    probes::load_probe(set, {}, &report);
    ASSERT_TRUE(report.cube) << set;
    EXPECT_EQ(report.layout, probes::Layout::kFaces);
    for (int f = 0; f < 6; ++f) {
      for (int i = 0; i < 16; ++i) {
        EXPECT_TRUE(
            report.cube->texel(f, i % 4, i / 4).isApprox(cube.texel(f, i % 4, i / 4), 1e-2f))
            << set << " face " << f;
      }
    }
  }
  // A face of another size, and a missing face, are named.
  write_rgb(dir / "ny.exr", 2, 2, std::vector<Rgb>(4, Rgb::Ones()));
  try {
    probes::load_probe(dir);
    ADD_FAILURE() << "no error";
  } catch (const probes::ProbeError& e) {
    EXPECT_NE(std::string(e.what()).find("ny.exr"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("same size"), std::string::npos) << e.what();
  }
  fs::remove(dir / "ny.exr");
  try {
    probes::load_probe(dir);
    ADD_FAILURE() << "no error";
  } catch (const probes::ProbeError& e) {
    EXPECT_NE(std::string(e.what()).find("ny."), std::string::npos) << e.what();
  }
}

TEST(CubeCross, WrongShapeForcedToCrossIsNamed) {
  const fs::path path = tmp_dir("shape") / "wide.exr";
  write_rgb(path, 8, 4, std::vector<Rgb>(32, Rgb::Ones()));
  probes::LoadOptions options;
  options.layout = probes::Layout::kCross;
  try {
    probes::load_probe(path, options);
    ADD_FAILURE() << "no error";
  } catch (const probes::ProbeError& e) {
    EXPECT_NE(std::string(e.what()).find("wide.exr"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cross"), std::string::npos) << e.what();
  }
}

}  // namespace
