// The view side of glossy transfer (prt/view_fit.h) and the oracles it is held to:
//  - the fits' algebra against a second code path (Eigen's QR of the stacked least-squares
//    system, the even extension by its definition, HSH's orthonormality);
//  - Smith masking against the microfacet projected-area identity;
//  - directional albedo in closed form;
//  - the engine's own bake of an unoccluded sphere against those albedos under a white sky,
//    against the diffuse path for Lambert, and against an exact per-pixel integral of a real
//    probe at several view angles.
#include "prt/view_fit.h"
#include "meshes/procedural.h"
#include "probes/load.h"
#include "prt/bake.h"
#include "prt/material.h"
#include "prt/projection.h"
#include "prt/sh.h"

#include <gtest/gtest.h>

#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <vector>

namespace {

constexpr double kPi = std::numbers::pi;

// Gauss-free hemisphere grid: midpoints in theta and phi, solid-angle weights. Fine enough
// that products of two order-6 functions integrate to ~1e-5.
void hemisphere_grid(int n_theta, int n_phi, Eigen::Matrix3Xd& dirs, Eigen::VectorXd& weights) {
  dirs.resize(3, n_theta * n_phi);
  weights.resize(n_theta * n_phi);
  for (int t = 0; t < n_theta; ++t) {
    const double theta = 0.5 * kPi * (t + 0.5) / n_theta;
    for (int p = 0; p < n_phi; ++p) {
      const double phi = 2 * kPi * (p + 0.5) / n_phi;
      const int k = t * n_phi + p;
      dirs.col(k) << std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
          std::cos(theta);
      weights[k] = std::sin(theta) * (0.5 * kPi / n_theta) * (2 * kPi / n_phi);
    }
  }
}

Eigen::MatrixXd basis_matrix(prt::ViewFit fit, int order, const Eigen::Matrix3Xd& dirs) {
  const int n = prt::sh_count(order);
  Eigen::MatrixXd y(n, dirs.cols());
  std::vector<double> v(n);
  for (Eigen::Index k = 0; k < dirs.cols(); ++k) {
    prt::view_basis_eval(fit, order, dirs.col(k), v.data());
    for (int i = 0; i < n; ++i) y(i, k) = v[i];
  }
  return y;
}

prt::Material cook_torrance(float roughness, prt::Masking masking = prt::Masking::kSmith) {
  prt::Material m;
  m.kind = prt::MaterialKind::kCookTorrance;
  m.albedo.setZero();
  m.specular = 1.f;
  m.f0 = 1.f;
  m.roughness = roughness;
  m.masking = masking;
  return m;
}

prt::Material lambert(float albedo) {
  prt::Material m;
  m.kind = prt::MaterialKind::kLambert;
  m.albedo.setConstant(albedo);
  m.specular = 0.f;
  return m;
}

prt::TransferSet bake_sphere(const meshes::Mesh& sphere, const prt::Material& m, int order,
                             prt::ViewFit fit,
                             prt::TransferKind kind = prt::TransferKind::kGlossy) {
  prt::BakeOptions o;
  o.kind = kind;
  o.order = order;
  o.samples = 4096;
  o.bounces = 0;
  o.material = m;
  o.view_fit = fit;
  return prt::bake(sphere, o);
}

Eigen::Vector3d local_of(const meshes::Mesh& mesh, std::size_t p, const Eigen::Vector3d& w) {
  return {mesh.tangents[p].cast<double>().dot(w), mesh.bitangents[p].cast<double>().dot(w),
          mesh.normals[p].cast<double>().dot(w)};
}

// Radiance as the renderers compute it: view clamped to the horizon, SH view basis.
Eigen::Vector3d glossy_radiance(const prt::TransferSet& t, const meshes::Mesh& mesh, std::size_t p,
                                const prt::ShLighting& l, const Eigen::Vector3d& w) {
  const int n = t.coefficient_count();
  std::vector<double> y(n);
  prt::sh_eval(t.order, prt::clamp_to_horizon(local_of(mesh, p, w)), y.data());
  const Eigen::RowVectorXd row =
      Eigen::Map<const Eigen::RowVectorXd>(y.data(), n) * t.transfer(p, 0).cast<double>();
  return (row * l).transpose();
}

Eigen::Vector3d view_at(const meshes::Mesh& mesh, std::size_t p, double degrees, double phi) {
  const double th = degrees * kPi / 180.0;
  return (std::cos(th) * mesh.normals[p].cast<double>() +
          std::sin(th) * (std::cos(phi) * mesh.tangents[p].cast<double>() +
                          std::sin(phi) * mesh.bitangents[p].cast<double>()))
      .normalized();
}

// --- The fits' algebra ------------------------------------------------------------------------

TEST(ViewFit, NamesRoundTrip) {
  for (prt::ViewFit f : {prt::ViewFit::kHemisphere, prt::ViewFit::kEven,
                         prt::ViewFit::kLeastSquares, prt::ViewFit::kHemisphericalHarmonics})
    EXPECT_EQ(prt::kViewFitNames.parse(prt::kViewFitNames.name(f)), f);
  EXPECT_THROW(prt::kViewFitNames.parse("bogus"), std::invalid_argument);
  EXPECT_FALSE(prt::view_fit_renderable(prt::ViewFit::kHemisphericalHarmonics));
  EXPECT_TRUE(prt::view_fit_renderable(prt::kDefaultViewFit));
}

TEST(ViewFit, HemisphericalHarmonicsAreOrthonormalOnTheHemisphere) {
  Eigen::Matrix3Xd dirs;
  Eigen::VectorXd w;
  hemisphere_grid(400, 64, dirs, w);
  const Eigen::MatrixXd h = basis_matrix(prt::ViewFit::kHemisphericalHarmonics, 6, dirs);
  const Eigen::MatrixXd gram = h * w.asDiagonal() * h.transpose();
  EXPECT_LT((gram - Eigen::MatrixXd::Identity(36, 36)).cwiseAbs().maxCoeff(), 2e-3);
  // The SH are not: their hemisphere Gram is far from I (that is why a projection steps).
  const Eigen::MatrixXd y = basis_matrix(prt::ViewFit::kHemisphere, 6, dirs);
  EXPECT_GT((y * w.asDiagonal() * y.transpose() - 0.5 * Eigen::MatrixXd::Identity(36, 36))
                .cwiseAbs()
                .maxCoeff(),
            0.1);
}

TEST(ViewFit, LeastSquaresSolvesTheStackedSystemByQr) {
  // A second code path: min || sqrt(W) (Y^T c - g) ||^2 + lambda sum l (l + 1) c_i^2 as one
  // tall least-squares problem solved by Householder QR, column by column of a random F.
  const int order = 5, n = prt::sh_count(order);
  Eigen::Matrix3Xd dirs;
  Eigen::VectorXd w;
  hemisphere_grid(24, 32, dirs, w);
  const double lambda = 3e-3;
  const Eigen::MatrixXd p =
      prt::view_projection(prt::ViewFit::kLeastSquares, order, dirs, w, lambda);
  const Eigen::MatrixXd y = basis_matrix(prt::ViewFit::kHemisphere, order, dirs);
  Eigen::MatrixXd stacked = Eigen::MatrixXd::Zero(dirs.cols() + n, n);
  stacked.topRows(dirs.cols()) = w.cwiseSqrt().asDiagonal() * y.transpose();
  for (int i = 0; i < n; ++i) {
    const int l = prt::sh_band(i);
    stacked(dirs.cols() + i, i) = std::sqrt(lambda * l * (l + 1));
  }
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(stacked);
  const Eigen::MatrixXd g = Eigen::MatrixXd::Random(dirs.cols(), 3);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(dirs.cols() + n, 3);
  rhs.topRows(dirs.cols()) = w.cwiseSqrt().asDiagonal() * g;
  const Eigen::MatrixXd expected = qr.solve(rhs);
  EXPECT_LT((p * g - expected).cwiseAbs().maxCoeff(), 1e-8 * expected.cwiseAbs().maxCoeff());
  EXPECT_THROW(prt::view_projection(prt::ViewFit::kLeastSquares, order, dirs, w, 0.0),
               std::invalid_argument);
}

TEST(ViewFit, EvenFitIsTheProjectionOfTheMirroredFunction) {
  // g(v) = e^{v.x + 2 v.z} on the upper hemisphere, mirrored below: project the mirrored
  // function over the whole sphere directly and compare.
  const int order = 6, n = prt::sh_count(order);
  Eigen::Matrix3Xd upper;
  Eigen::VectorXd w;
  hemisphere_grid(200, 128, upper, w);
  const auto g = [](const Eigen::Vector3d& v) { return std::exp(v.x() + 2 * std::abs(v.z())); };
  Eigen::VectorXd gv(upper.cols());
  for (Eigen::Index k = 0; k < upper.cols(); ++k) gv[k] = g(upper.col(k));
  const Eigen::VectorXd even = prt::view_projection(prt::ViewFit::kEven, order, upper, w) * gv;
  Eigen::VectorXd direct = Eigen::VectorXd::Zero(n);
  std::vector<double> y(n);
  for (Eigen::Index k = 0; k < upper.cols(); ++k) {
    for (double sign : {1.0, -1.0}) {
      const Eigen::Vector3d v(upper(0, k), upper(1, k), sign * upper(2, k));
      prt::sh_eval(order, v, y.data());
      for (int i = 0; i < n; ++i) direct[i] += y[i] * g(v) * w[k];
    }
  }
  EXPECT_LT((even - direct).cwiseAbs().maxCoeff(), 1e-10 * direct.cwiseAbs().maxCoeff());
  for (int l = 0; l < order; ++l) {
    for (int m = -l; m <= l; ++m) {
      if ((l + m) % 2) {
        EXPECT_EQ(even[prt::sh_index(l, m)], 0.0);
      }
    }
  }
}

TEST(ViewFit, ClampToHorizon) {
  EXPECT_EQ(prt::clamp_to_horizon(Eigen::Vector3d(0.6, 0, 0.8)), Eigen::Vector3d(0.6, 0, 0.8));
  const Eigen::Vector3d c = prt::clamp_to_horizon(Eigen::Vector3d(0.3, 0.4, -0.866));
  EXPECT_NEAR(c.x(), 0.6, 1e-12);
  EXPECT_NEAR(c.y(), 0.8, 1e-12);
  EXPECT_EQ(c.z(), 0.0);
  EXPECT_EQ(prt::clamp_to_horizon(Eigen::Vector3d(0, 0, -1)), Eigen::Vector3d(1, 0, 0));
}

// --- Masking and albedo -------------------------------------------------------------------------

TEST(Masking, SmithSatisfiesTheProjectedAreaIdentity) {
  // For Smith's G1, int G1(v) max(0, v.h) D(h) dh = v.z (Heitz 2014, eq. 18): the visible
  // microfacets project onto the view plane as the macro surface does. G1(v) is read off
  // brdf_eval with the light along the normal (Lambda = 0 there): f = D(h) G1(v) / (4 v.z)
  // with F = 1 (f0 = 1). D is Beckmann's closed form, written here again.
  for (float roughness : {0.2f, 0.5f, 0.9f}) {
    const prt::Material m = cook_torrance(roughness);
    const double m2 = double(roughness) * roughness;
    const auto beckmann = [&](double hz) {
      const double c2 = hz * hz, tan2 = (1 - c2) / c2;
      return std::exp(-tan2 / m2) / (kPi * m2 * c2 * c2);
    };
    for (double theta_deg : {10.0, 45.0, 70.0, 85.0}) {
      const double th = theta_deg * kPi / 180;
      const Eigen::Vector3d v(std::sin(th), 0, std::cos(th));
      const Eigen::Vector3d h = (v + Eigen::Vector3d::UnitZ()).normalized();
      const double g1 =
          prt::brdf_eval(m, 0, v, Eigen::Vector3d::UnitZ()) * 4 * v.z() / beckmann(h.z());
      EXPECT_GT(g1, 0.0);
      EXPECT_LE(g1, 1.0 + 1e-12);
      double projected = 0;
      const int nt = 2000, np = 256;
      for (int t = 0; t < nt; ++t) {
        const double ht = 0.5 * kPi * (t + 0.5) / nt;
        for (int p = 0; p < np; ++p) {
          const double hp = 2 * kPi * (p + 0.5) / np;
          const Eigen::Vector3d hh(std::sin(ht) * std::cos(hp), std::sin(ht) * std::sin(hp),
                                   std::cos(ht));
          projected += std::max(0.0, v.dot(hh)) * beckmann(hh.z()) * std::sin(ht) *
                       (0.5 * kPi / nt) * (2 * kPi / np);
        }
      }
      EXPECT_NEAR(g1 * projected, v.z(), 2e-3 * v.z())
          << "m " << roughness << " theta " << theta_deg;
    }
  }
  EXPECT_EQ(prt::kMaskingNames.parse(prt::kMaskingNames.name(prt::Masking::kVGroove)),
            prt::Masking::kVGroove);
  EXPECT_THROW(prt::kMaskingNames.parse("none"), std::invalid_argument);
}

TEST(DirectionalAlbedo, ClosedForms) {
  // Lambert: rho at every view. Modified Phong toward the normal: r.v = s.z, so the lobe
  // integrates (e + 2) / (2 pi) int s.z^(e+1) ds = 1: rho_d + rho_s exactly.
  EXPECT_NEAR(prt::directional_albedo(lambert(0.5f), 0, Eigen::Vector3d(0.6, 0, 0.8)), 0.5, 1e-5);
  prt::Material phong;
  phong.exponent = 32.f;
  EXPECT_NEAR(prt::directional_albedo(phong, 0, Eigen::Vector3d::UnitZ()), 0.8, 1e-4);
  // Smith never gains energy over V-groove toward the normal by much, and both stay <= 1.
  for (prt::Masking masking : {prt::Masking::kSmith, prt::Masking::kVGroove}) {
    for (double deg : {0.0, 40.0, 80.0}) {
      const double th = deg * kPi / 180;
      const double a = prt::directional_albedo(cook_torrance(0.5f, masking), 0,
                                               Eigen::Vector3d(std::sin(th), 0, std::cos(th)));
      EXPECT_GT(a, 0.5);
      EXPECT_LE(a, 1.0);
    }
  }
}

// --- The engine against the oracles -----------------------------------------------------------

TEST(GlossyFidelity, WhiteSkyMatchesDirectionalAlbedo) {
  // Constant unit sky over an unoccluded sphere: exit radiance is the directional albedo.
  // Target p99 over 0-70 degrees at order 6: 2% (Lambert), 3% (the others). Measured with the
  // default fit: 0.00%, 0.38% (m 0.5 Smith), 0.5% (V-groove), 1.36% (Phong e 32). The
  // thesis's projection gives +15.6% toward the normal for Lambert, which must fail here.
  const meshes::Mesh sphere = meshes::make_sphere(1.f, 12, 8);
  struct Case {
    prt::Material material;
    double bound;
  };
  const std::vector<Case> cases = {{lambert(0.5f), 0.02},
                                   {cook_torrance(0.5f), 0.03},
                                   {cook_torrance(0.5f, prt::Masking::kVGroove), 0.03},
                                   {prt::Material{}, 0.03}};
  prt::ShLighting white = prt::ShLighting::Zero(36, 3);
  white.row(0).setConstant(std::sqrt(4 * kPi));
  for (const Case& c : cases) {
    for (prt::ViewFit fit : {prt::kDefaultViewFit, prt::ViewFit::kHemisphere}) {
      const prt::TransferSet t = bake_sphere(sphere, c.material, 6, fit);
      double worst = 0;
      for (double deg = 0; deg <= 70; deg += 10) {
        const Eigen::Vector3d w = view_at(sphere, 0, deg, 0.0);
        const double exact = prt::directional_albedo(c.material, 0, local_of(sphere, 0, w));
        const double x = glossy_radiance(t, sphere, 0, white, w)[0];
        worst = std::max(worst, std::abs(x - exact) / exact);
      }
      std::cout << prt::kMaterialNames.name(c.material.kind) << " "
                << prt::kMaskingNames.name(c.material.masking) << " "
                << prt::kViewFitNames.name(fit) << ": worst white-sky error " << worst << "\n";
      if (fit == prt::kDefaultViewFit) {
        EXPECT_LT(worst, c.bound) << prt::kMaterialNames.name(c.material.kind);
      } else if (c.material.kind == prt::MaterialKind::kLambert) {
        EXPECT_GT(worst, 0.1);
      }
    }
  }
}

TEST(GlossyFidelity, LambertThroughTheGlossyPathEqualsTheDiffusePath) {
  // The glossy path's Lambert radiance is the same at every view (the fit holds the constant
  // exactly, and views past the horizon are clamped onto it), and it equals the diffuse
  // path's up to the light side: the glossy path applies the clamped cosine's order-6
  // truncation to the visible light, the diffuse path the cosine itself (measured: 0.52% of
  // the largest radiance under random lighting; exactly equal under a white sky, above).
  const meshes::Mesh sphere = meshes::make_sphere(1.f, 12, 8);
  const int order = 6, n = prt::sh_count(order);
  const prt::TransferSet glossy = bake_sphere(sphere, lambert(0.6f), order, prt::kDefaultViewFit);
  const prt::TransferSet diffuse =
      bake_sphere(sphere, lambert(0.6f), order, prt::kDefaultViewFit, prt::TransferKind::kDiffuse);
  prt::ShLighting l = prt::ShLighting::Random(n, 3);
  l.row(0) += Eigen::RowVector3d::Constant(4.0);
  double across_views = 0, across_paths = 0, scale = 0;
  for (std::size_t p = 0; p < sphere.vertex_count(); p += 7) {
    const Eigen::Vector3d d = (diffuse.transfer(p, 0).cast<double>().transpose() * l).transpose();
    const Eigen::Vector3d g0 = glossy_radiance(glossy, sphere, p, l, view_at(sphere, p, 0, 0));
    for (double deg : {35.0, 70.0, 89.0, 100.0}) {
      const Eigen::Vector3d g = glossy_radiance(glossy, sphere, p, l, view_at(sphere, p, deg, 1.0));
      across_views = std::max(across_views, (g - g0).cwiseAbs().maxCoeff());
    }
    across_paths = std::max(across_paths, (g0 - d).cwiseAbs().maxCoeff());
    scale = std::max(scale, d.cwiseAbs().maxCoeff());
  }
  std::cout << "across views " << across_views / scale << ", glossy vs diffuse "
            << across_paths / scale << " of the largest radiance\n";
  EXPECT_LT(across_views, 1e-5 * scale);
  EXPECT_LT(across_paths, 1e-2 * scale);
}

const std::filesystem::path kForest = "/usr/share/blender/datafiles/studiolights/world/forest.exr";

struct ProbeCase {
  std::vector<std::size_t> vertices;
  std::vector<double> angles;
  std::vector<Eigen::Vector3d> views, exact;
  std::vector<std::size_t> vertex_of;
};

// The exact per-pixel integral sum f_r(v, s) L(s) max(0, n.s) dOmega for each view.
ProbeCase exact_probe_case(const meshes::Mesh& sphere, const probes::Probe& probe,
                           const prt::Material& m) {
  ProbeCase c;
  c.angles = {0, 30, 60, 75};
  int k = 0;
  for (std::size_t p = 3; p < sphere.vertex_count(); p += 9) {
    for (double deg : c.angles) {
      c.views.push_back(view_at(sphere, p, deg, 2.399963 * k++));
      c.vertex_of.push_back(p);
    }
  }
  for (std::size_t i = 0; i < c.views.size(); ++i) {
    const std::size_t p = c.vertex_of[i];
    const Eigen::Vector3d n = sphere.normals[p].cast<double>();
    const Eigen::Vector3d v = local_of(sphere, p, c.views[i]);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int y = 0; y < probe.height(); ++y) {
      const double d_omega = probe.pixel_solid_angle(y);
      for (int x = 0; x < probe.width(); ++x) {
        const Eigen::Vector3d s = probe.pixel_direction(x, y);
        const double cosine = n.dot(s);
        if (cosine <= 0) continue;
        sum += prt::brdf_eval(m, 0, v, local_of(sphere, p, s)) * cosine * d_omega *
               probe.texel(x, y).cast<double>();
      }
    }
    c.exact.push_back(sum);
  }
  return c;
}

struct ErrorPair {
  double rmse, bias;
};

ErrorPair probe_error(const prt::TransferSet& t, const meshes::Mesh& sphere,
                      const prt::ShLighting& l, const ProbeCase& c) {
  double se = 0, sr = 0, d = 0, r = 0;
  for (std::size_t i = 0; i < c.views.size(); ++i) {
    const Eigen::Vector3d x = glossy_radiance(t, sphere, c.vertex_of[i], l, c.views[i]);
    se += (x - c.exact[i]).squaredNorm();
    sr += c.exact[i].squaredNorm();
    d += (x - c.exact[i]).sum();
    r += c.exact[i].sum();
  }
  return {std::sqrt(se / sr), d / r};
}

TEST(GlossyFidelity, RealProbeMatchesTheExactIntegralAndConvergesWithOrder) {
  // Cook-Torrance m 0.5 (Smith) under Blender's forest probe, views 0-75 degrees from the
  // normal. Targets at order 6: relative RMSE <= 5%, |bias| <= 1% (measured 3.3% and
  // -0.02%; the thesis's projection: 11% and +3.5%); the error falls at every order step.
  if (!std::filesystem::exists(kForest)) GTEST_SKIP() << kForest << " missing (blender-data)";
  const probes::Probe probe = probes::load_probe(kForest);
  const meshes::Mesh sphere = meshes::make_sphere(1.f, 16, 10);
  const prt::Material m = cook_torrance(0.5f);
  const ProbeCase c = exact_probe_case(sphere, probe, m);
  double previous = 1e9;
  for (int order : {2, 4, 6, 8, 10}) {
    const prt::ShLighting l = prt::project(probe, order);
    const ErrorPair e =
        probe_error(bake_sphere(sphere, m, order, prt::kDefaultViewFit), sphere, l, c);
    std::cout << "order " << order << ": relative RMSE " << e.rmse << ", bias " << e.bias << "\n";
    EXPECT_LT(e.rmse, previous) << "order " << order;
    previous = e.rmse;
    if (order == 6) {
      EXPECT_LT(e.rmse, 0.05);
      EXPECT_LT(std::abs(e.bias), 0.01);
      const ErrorPair thesis =
          probe_error(bake_sphere(sphere, m, order, prt::ViewFit::kHemisphere), sphere, l, c);
      std::cout << "  thesis's projection: relative RMSE " << thesis.rmse << ", bias "
                << thesis.bias << "\n";
      EXPECT_GT(thesis.rmse, 1.5 * e.rmse);
    }
  }
}

}  // namespace
