// A cube with hard edges under a sky that is white above the horizon and black below: the
// exact diffuse exit radiance of a Lambert surface of albedo rho is rho on the top face
// (irradiance pi), rho / 2 on every side face (half the sky above the horizon, irradiance
// pi / 2) and 0 on the bottom, flat across each face. Corner normals smoothed across the
// cube's 90-degree edges point diagonally and give gradients instead, so this checks the
// loader's crease splitting end to end through the bake.
#include "prt/bake.h"

#include "meshes/load.h"
#include "prt/sh.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <numbers>
#include <vector>

namespace {

// SH coefficients of the sky (radiance 1 where y > 0), by a Fibonacci-sphere quadrature.
std::vector<double> upper_sky(int order) {
  const int n = prt::sh_count(order);
  std::vector<double> coefficients(std::size_t(n), 0.0);
  std::vector<double> y(std::size_t(n), 0.0);
  constexpr int kPoints = 400000;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < kPoints; ++i) {
    const double dy = 1.0 - (i + 0.5) * 2.0 / kPoints;
    if (dy <= 0) continue;
    const double r = std::sqrt(1.0 - dy * dy);
    prt::sh_eval(order, r * std::cos(golden * i), dy, r * std::sin(golden * i), y.data());
    for (int k = 0; k < n; ++k) coefficients[std::size_t(k)] += y[std::size_t(k)];
  }
  for (double& c : coefficients) c *= 4.0 * std::numbers::pi / kPoints;
  return coefficients;
}

TEST(CreaseBake, CubeUnderUpperSkyMatchesExactFaceValues) {
  const auto path = test_support::scratch("crease_bake", "cube.obj");
  std::ofstream(path) << test_support::cube_obj(false);
  meshes::LoadOptions auto_smooth;
  auto_smooth.crease_angle_deg = 30;  // Blender's auto smooth; the default is all smooth
  const meshes::Mesh mesh = meshes::load_mesh(path, auto_smooth);

  prt::BakeOptions o;
  o.kind = prt::TransferKind::kDiffuse;
  o.material.kind = prt::MaterialKind::kLambert;
  o.material.albedo = Eigen::Vector3f::Constant(0.5f);
  o.material.specular = 0.f;
  o.order = 6;
  o.samples = 1024;
  o.bounces = 0;
  const prt::TransferSet t = prt::bake(mesh, o);
  const std::vector<double> sky = upper_sky(o.order);

  std::vector<double> distance;  // relative to the face's exact value
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    double radiance = 0;
    for (int k = 0; k < t.coefficient_count(); ++k)
      radiance += t.transfer(v, 0)(k, 0) * sky[std::size_t(k)];
    const float ny = mesh.normals[v].y();
    if (ny < -0.5f) {
      EXPECT_NEAR(radiance, 0.0, 0.01) << "bottom vertex " << v;
      continue;
    }
    const double exact = ny > 0.5f ? 0.5 : 0.25;
    distance.push_back(std::abs(radiance - exact) / exact);
  }
  ASSERT_EQ(distance.size(), 20u);  // 4 top + 16 side vertices
  std::sort(distance.begin(), distance.end());
  const double p97 = distance[std::size_t(std::ceil(0.97 * double(distance.size()))) - 1];
  std::cout << "cube under the upper sky: p97 distance from exact " << p97 << ", max "
            << distance.back() << "\n";
  EXPECT_LE(p97, 0.03);
}

}  // namespace
