// The GLM camera against the hand-written matrices it replaced, and against pixels known
// from the geometry of a pinhole; the Eigen <-> GLM crossing element by element.
#include "render/camera.h"
#include "render/glm_eigen.h"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <numbers>

namespace {

// The matrices as they were written before GLM (gluLookAt and gluPerspective by hand).
Eigen::Matrix4d old_view(const render::Camera& c) {
  const Eigen::Vector3d f = (c.target - c.eye).normalized();
  const Eigen::Vector3d r = f.cross(c.up).normalized();
  const Eigen::Vector3d u = r.cross(f);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<1, 3>(0, 0) = r.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -r.dot(c.eye);
  m(1, 3) = -u.dot(c.eye);
  m(2, 3) = f.dot(c.eye);
  return m;
}

Eigen::Matrix4d old_projection(const render::Camera& c) {
  const double t = std::tan(0.5 * c.fov_y_degrees * std::numbers::pi / 180.0);
  const double n = c.near_plane, f = c.far_plane;
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = 1.0 / (t * c.aspect());
  m(1, 1) = 1.0 / t;
  m(2, 2) = -(f + n) / (f - n);
  m(2, 3) = -2.0 * f * n / (f - n);
  m(3, 2) = -1.0;
  return m;
}

render::Camera oblique_camera() {
  render::Camera c;
  c.eye = Eigen::Vector3d(1.5, -2.0, 4.0);
  c.target = Eigen::Vector3d(0.2, 0.3, -0.1);
  c.up = Eigen::Vector3d(0.1, 1.0, 0.2);
  c.fov_y_degrees = 35.0;
  c.width = 640;
  c.height = 360;
  c.near_plane = 0.5;
  c.far_plane = 20.0;
  return c;
}

// Image pixel coordinates (row 0 at the top) of a world point.
Eigen::Vector2d pixel_of(const render::Camera& c, const Eigen::Vector3d& p) {
  const Eigen::Vector4d clip = c.clip_from_world() * p.homogeneous();
  const Eigen::Vector2d ndc = clip.head<2>() / clip.w();
  return {0.5 * (ndc.x() + 1.0) * c.width, 0.5 * (1.0 - ndc.y()) * c.height};
}

TEST(Camera, GlmMatricesEqualTheHandWrittenOnes) {
  for (const render::Camera& c : {render::Camera{}, oblique_camera()}) {
    EXPECT_LE((c.view_from_world() - old_view(c)).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LE((c.clip_from_view() - old_projection(c)).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(Camera, ProjectsKnownPointsToTheirPixels) {
  const render::Camera c = oblique_camera();
  const Eigen::Vector2d centre = pixel_of(c, c.target);
  EXPECT_NEAR(centre.x(), 320.0, 1e-9);
  EXPECT_NEAR(centre.y(), 180.0, 1e-9);
  // A point on the top edge of the view cone, and one on the right edge, at distance 3.
  const Eigen::Vector3d f = (c.target - c.eye).normalized();
  const Eigen::Vector3d r = f.cross(c.up).normalized();
  const Eigen::Vector3d u = r.cross(f);
  const double t = std::tan(0.5 * c.fov_y_degrees * std::numbers::pi / 180.0);
  const Eigen::Vector2d top = pixel_of(c, c.eye + 3.0 * (f + t * u));
  EXPECT_NEAR(top.x(), 320.0, 1e-9);
  EXPECT_NEAR(top.y(), 0.0, 1e-9);
  const Eigen::Vector2d right = pixel_of(c, c.eye + 3.0 * (f + t * c.aspect() * r));
  EXPECT_NEAR(right.x(), 640.0, 1e-9);
  EXPECT_NEAR(right.y(), 180.0, 1e-9);
  // The near and far planes map to depth -1 and 1.
  for (auto [distance, ndc_z] : {std::pair{c.near_plane, -1.0}, std::pair{c.far_plane, 1.0}}) {
    const Eigen::Vector4d clip = c.clip_from_world() * (c.eye + distance * f).homogeneous();
    EXPECT_NEAR(clip.z() / clip.w(), ndc_z, 1e-12);
  }
}

// The rays a path tracer sends through a pixel pass where the raster samples it: pixel
// (x, y) spans [x, x + 1] x [y, y + 1] in window coordinates from the top, its centre at
// + 0.5, and sample (i, j) of n x n at the centre of its sub-pixel (what an n-times
// supersampled frame rasterises), checked through the projection matrix the GL path uses.
TEST(Camera, PixelAndSubpixelRaysPassThroughTheRasterisedPositions) {
  const render::Camera c = oblique_camera();
  for (const auto& [x, y] : {std::pair{0, 0}, std::pair{17, 203}, std::pair{639, 359}}) {
    const Eigen::Vector2d centre = pixel_of(c, c.eye + 2.0 * c.pixel_direction(x, y));
    EXPECT_NEAR(centre.x(), x + 0.5, 1e-9);
    EXPECT_NEAR(centre.y(), y + 0.5, 1e-9);
    for (const int n : {1, 3, 8})
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const Eigen::Vector2d p = pixel_of(c, c.eye + 2.0 * c.subpixel_direction(x, y, i, j, n));
          EXPECT_NEAR(p.x(), x + (i + 0.5) / n, 1e-9) << n;
          EXPECT_NEAR(p.y(), y + (j + 0.5) / n, 1e-9) << n;
        }
  }
}

TEST(GlmEigen, MatricesAndVectorsCrossElementForElement) {
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = i;  // row r, column c holds 4r + c
  const glm::dmat4 g = render::to_glm(m);
  EXPECT_EQ(g[3][0], 3.0);  // column 3, row 0: the x translation
  EXPECT_EQ(g[0][3], 12.0);
  EXPECT_EQ(render::to_eigen(g), m);
  Eigen::Matrix3d m3;
  for (int i = 0; i < 9; ++i) m3(i / 3, i % 3) = i;
  EXPECT_EQ(render::to_glm(m3)[2][0], 2.0);  // column 2, row 0
  const Eigen::Vector3d v(1, -2, 3);
  EXPECT_EQ(render::to_eigen(render::to_glm(v)), v);
  const glm::dvec4 gv = g * glm::dvec4(1, 0, 0, 0);
  const Eigen::Vector4d ev = m * Eigen::Vector4d(1, 0, 0, 0);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(gv[i], ev[i]);
}

}  // namespace
